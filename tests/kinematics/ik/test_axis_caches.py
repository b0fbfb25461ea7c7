"""The module caches keyed by an axis (unit axes, axis frames, cross matrices) stay bounded whatever axes callers
sweep over, and keep answering correctly once full."""

from __future__ import annotations

import numpy as np

from service.kinematics._cache import AxisCache
from service.kinematics.ik import _screws
from service.kinematics.ik.subproblems import _vectors


def test_a_sweep_over_many_axes_keeps_at_most_the_bound(monkeypatch):
    kept = 8
    for module, cache in ((_screws, "_FRAMES"), (_screws, "_CROSS"), (_vectors, "_UNITS")):
        monkeypatch.setattr(module, cache, AxisCache(kept))
    rng = np.random.default_rng(7)
    axes = rng.normal(size=(3 * kept, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    for k in axes:
        frame = _screws.axis_frame(k)
        np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-15)
        np.testing.assert_array_equal(frame[:, 2], k)
        R = _screws.rotation_about(k, np.array(0.7))
        np.testing.assert_allclose(R @ k, k, atol=1e-15)
        np.testing.assert_allclose(_screws.rotate_about(k, 0.7, np.cross(k, [1.0, 0, 0])),
                                   R @ np.cross(k, [1.0, 0, 0]), atol=1e-15)
        np.testing.assert_allclose(_vectors._unit(k, "k"), k, rtol=0, atol=1e-15)
    assert len(_screws._FRAMES) == len(_screws._CROSS) == len(_vectors._UNITS) == kept
