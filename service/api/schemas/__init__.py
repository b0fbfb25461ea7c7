"""Pydantic v2 request and response models: the API's wire format."""
