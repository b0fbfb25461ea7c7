"""OPW arms (Brandstötter, Angerer & Hofbaur 2014): their forward kinematics, written from the seven OPW
parameters, and the catalogue OPW arms' parameters, sign corrections and joint offsets as their sources give them
(theta_opw = sign * q - offset). Nothing here uses the service."""

from __future__ import annotations

import math

import numpy as np

from tests.oracles.rotations import about

#: robot id -> the source's OPW parameters (m), sign corrections and joint offsets (deg); sources in the YAML files.
OPW_SOURCES = {
    "kuka_kr6_r900_2": (dict(a1=0.025, a2=-0.025, b=0.0, c1=0.400, c2=0.455, c3=0.420, c4=0.090),
                        (-1, 1, 1, -1, 1, -1), (0, -90, 0, 0, 0, 0)),
    "kuka_kr210_r2700": (dict(a1=0.350, a2=0.041, b=0.0, c1=0.675, c2=1.150, c3=1.200, c4=0.215),
                         (-1, 1, 1, -1, 1, -1), (0, -90, 0, 0, 0, 0)),
    "abb_irb120": (dict(a1=0.0, a2=-0.070, b=0.0, c1=0.290, c2=0.270, c3=0.302, c4=0.072),
                   (1, 1, 1, 1, 1, 1), (0, 0, -90, 0, 0, 0)),
    "abb_irb6700": (dict(a1=0.320, a2=-0.200, b=0.0, c1=0.780, c2=1.125, c3=1.1425, c4=0.200),
                    (1, 1, 1, 1, 1, 1), (0, 0, -90, 0, 0, 0)),
    "fanuc_lrmate200id": (dict(a1=0.050, a2=-0.035, b=0.0, c1=0.330, c2=0.330, c3=0.335, c4=0.080),
                          (1, 1, -1, -1, -1, -1), (0, 0, -90, 0, 0, 180)),
}


def opw_forward(p: dict, signs, offsets_deg, q: np.ndarray) -> np.ndarray:
    """Base_T_flange (4, 4) of an OPW arm at controller angles q (rad), after Brandstötter et al. 2014, eqs. for C and u."""
    t = np.asarray(signs) * q - np.radians(offsets_deg)
    psi3 = math.atan2(p["a2"], p["c3"])
    k = math.hypot(p["a2"], p["c3"])
    cx1 = p["c2"] * math.sin(t[1]) + k * math.sin(t[1] + t[2] + psi3) + p["a1"]
    cy1 = p["b"]
    cz1 = p["c2"] * math.cos(t[1]) + k * math.cos(t[1] + t[2] + psi3)
    c = np.array([cx1 * math.cos(t[0]) - cy1 * math.sin(t[0]), cx1 * math.sin(t[0]) + cy1 * math.cos(t[0]),
                  cz1 + p["c1"]])
    rotation = about("z", t[0]) @ about("y", t[1] + t[2]) @ about("z", t[3]) @ about("y", t[4]) @ about("z", t[5])
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:3, 3] = c + p["c4"] * rotation[:, 2]
    return pose
