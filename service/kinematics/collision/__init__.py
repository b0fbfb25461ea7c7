"""Collision geometry and distances: link shapes, obstacles, and the signed clearance of joint vectors.

Pure numpy. Shapes are values (:mod:`._shapes`); distances are vectorised over
configurations × shape pairs.
"""

from ._shapes import Box, Capsule, LinkShape, Obstacle, Shape, Sphere, restated, scaled

__all__ = ["Box", "Capsule", "LinkShape", "Obstacle", "Shape", "Sphere", "restated", "scaled"]
