"""Collision geometry and distances: link shapes, obstacles, and the signed clearance of joint vectors.

Pure numpy. Shapes are values (:mod:`._shapes`). Signed distances between two shapes, vectorised over any batch,
with witness points (:mod:`._distances`: positive apart, minus the penetration depth in overlap). A compiled
model of a robot's shape pairs and the obstacles, evaluated for link frames (S, n + 1, 4, 4) into distances
(S, P), clearances and the pairs closer than a margin (:mod:`._model`).
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
from ._clearance import (Clearances, CollisionRequest, Contacts, at_collisions, clearances, colliding, frame_index,
                         link_names, model_for, model_is_kept)
from ._model import CollisionCheck, CollisionModel, ShapePair, collision_model
from ._shapes import Box, Capsule, LinkShape, Obstacle, Shape, Sphere, restated, scaled

__all__ = [
    "Box",
    "Capsule",
    "Clearances",
    "CollisionRequest",
    "CollisionCheck",
    "CollisionModel",
    "Contacts",
    "LinkShape",
    "Obstacle",
    "Separation",
    "Shape",
    "ShapePair",
    "Sphere",
    "at_collisions",
    "box_box",
    "box_capsule",
    "box_sphere",
    "capsule_capsule",
    "capsule_sphere",
    "clearances",
    "colliding",
    "collision_model",
    "frame_index",
    "link_names",
    "model_for",
    "model_is_kept",
    "restated",
    "scaled",
    "separation",
    "sphere_sphere",
]
