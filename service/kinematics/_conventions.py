"""Link transforms of the three Denavit–Hartenberg conventions.

Every convention is reduced here, and only here, to one closed-form 4×4 link
transform. The rest of the core never branches on the convention.

* ``"standard"`` (Spong, Paul): row i holds (a_i, alpha_i, d_i, theta_i) and
  ``A_i = Rot_z(theta_i) · Trans_z(d_i) · Trans_x(a_i) · Rot_x(alpha_i)``.
* ``"modified"`` (Craig): row i holds (a_{i-1}, alpha_{i-1}, d_i, theta_i) and
  ``T_i = Rot_x(alpha_{i-1}) · Trans_x(a_{i-1}) · Rot_z(theta_i) · Trans_z(d_i)``.
* ``"khalil"`` (Khalil–Kleinfinger): row j holds (alpha_j, d_j, theta_j, r_j),
  ``T_j = Rot_x(alpha_j) · Trans_x(d_j) · Rot_z(theta_j) · Trans_z(r_j)``. The
  frames are Craig's, so a Khalil row is a Craig row renamed: ``a = d_j`` and
  ``d = r_j`` (textbook.md §1.3). :func:`craig_row_from_khalil` does the renaming
  once, when a robot is built.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

Convention = Literal["standard", "modified", "khalil"]
CONVENTIONS: tuple[Convention, ...] = ("standard", "modified", "khalil")


def craig_row_from_khalil(alpha_j: float, d_j: float, theta_j: float, r_j: float) -> tuple[float, float, float, float]:
    """Rename a Khalil–Kleinfinger row to the Craig row (a, alpha, d, theta) of the same frame."""
    return d_j, alpha_j, r_j, theta_j


def link_transforms(
    convention: Convention,
    a: np.ndarray,
    alpha: np.ndarray,
    d: np.ndarray,
    theta: np.ndarray,
) -> np.ndarray:
    """Link transforms for rows of DH parameters, in closed form.

    Parameters
    ----------
    convention : {"standard", "modified", "khalil"}
        For ``"khalil"`` the rows must already be renamed to Craig's
        (a, alpha, d, theta) with :func:`craig_row_from_khalil`.
    a, alpha, d, theta : array_like, broadcastable to a common shape (..., n)
        Link parameters. Angles in radians.

    Returns
    -------
    ndarray, shape (..., n, 4, 4)
        ``prev_T_link`` for each row: frame i-1 to frame i.

    Examples
    --------
    >>> T = link_transforms("standard", [1.0], [0.0], [0.0], [np.pi / 2])
    >>> np.round(T[0, :2, 3], 12).tolist()
    [0.0, 1.0]
    """
    a, alpha, d, theta = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (a, alpha, d, theta)))
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    T = np.zeros(a.shape + (4, 4))
    T[..., 3, 3] = 1.0
    if convention == "standard":
        T[..., 0, 0] = ct
        T[..., 0, 1] = -st * ca
        T[..., 0, 2] = st * sa
        T[..., 0, 3] = a * ct
        T[..., 1, 0] = st
        T[..., 1, 1] = ct * ca
        T[..., 1, 2] = -ct * sa
        T[..., 1, 3] = a * st
        T[..., 2, 1] = sa
        T[..., 2, 2] = ca
        T[..., 2, 3] = d
    elif convention in ("modified", "khalil"):
        T[..., 0, 0] = ct
        T[..., 0, 1] = -st
        T[..., 0, 3] = a
        T[..., 1, 0] = st * ca
        T[..., 1, 1] = ct * ca
        T[..., 1, 2] = -sa
        T[..., 1, 3] = -sa * d
        T[..., 2, 0] = st * sa
        T[..., 2, 1] = ct * sa
        T[..., 2, 2] = ca
        T[..., 2, 3] = ca * d
    else:
        raise ValueError(f"unknown convention {convention!r}; expected one of {CONVENTIONS}")
    return T
