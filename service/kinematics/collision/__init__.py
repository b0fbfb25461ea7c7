"""Collision geometry and distances: link shapes, obstacles, and the signed clearance of joint vectors.

Pure numpy. Shapes are values (:mod:`._shapes`); distances are vectorised over
configurations × shape pairs.
"""

from ._distances import (
    Separation,
    box_box,
    box_capsule,
    box_sphere,
    capsule_capsule,
    capsule_sphere,
    separation,
    sphere_sphere,
)
from ._model import CollisionCheck, CollisionModel, ShapePair, collision_model
from ._shapes import Box, Capsule, LinkShape, Obstacle, Shape, Sphere

__all__ = [
    "Box",
    "Capsule",
    "CollisionCheck",
    "CollisionModel",
    "LinkShape",
    "Obstacle",
    "Separation",
    "Shape",
    "ShapePair",
    "Sphere",
    "box_box",
    "box_capsule",
    "box_sphere",
    "capsule_capsule",
    "capsule_sphere",
    "collision_model",
    "separation",
    "sphere_sphere",
]
