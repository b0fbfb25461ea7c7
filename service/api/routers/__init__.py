"""Thin routers: each translates a request into core calls and the result back."""
