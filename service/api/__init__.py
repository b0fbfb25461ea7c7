"""The HTTP layer: schemas, routers and error handling around the kinematics core."""
