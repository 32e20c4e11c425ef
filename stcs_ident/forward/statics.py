"""Static profile of a shallow cable with point masses (vectorised).

Between attachments y'' = -w/H; at attachment k the slope drops by
a_k = M_k g cos θ / H; y(0) = y(l) = 0. Everything here works on arrays
whose leading axes are a batch of configurations.
"""

from __future__ import annotations

import numpy as np

# 16-point Gauss–Legendre on [0, 1]: (1 + y'^2)^(3/2) with y' linear on a
# segment is analytic with singularities at y' = ±i, far from the real
# slopes of a shallow cable (|y'| < 0.5), so 16 points reach round-off.
_GL_T, _GL_W = np.polynomial.legendre.leggauss(16)
_GL_T = 0.5 * (_GL_T + 1.0)
_GL_W = 0.5 * _GL_W


def end_slopes(length, positions, w_over_h, kinks):
    """Slopes of the static profile at both ends of every segment.

    Parameters
    ----------
    length : array (...,)
        Chord length l.
    positions : array (..., n_att)
        Attachment positions, ascending.
    w_over_h : array (...,)
        w / H (1/m).
    kinks : array (..., n_att)
        Slope drop at each attachment, M_k g cos θ / H.

    Returns
    -------
    seg_len, slope_start, slope_end : arrays (..., n_att + 1)
        Segment lengths, y'(x_j+) and y'(x_{j+1}-).
    """
    length = np.asarray(length, float)
    nodes = np.concatenate([np.zeros(length.shape + (1,)), positions, length[..., None]], axis=-1)
    seg_len = nodes[..., 1:] - nodes[..., :-1]
    # y(l) = 0  <=>  ∫ y' dx = 0  (np.add.reduce/accumulate: np.sum/np.cumsum without their Python layer)
    y0 = 0.5 * w_over_h * length + np.add.reduce(kinks * (length[..., None] - positions), axis=-1) / length
    drop_before = np.concatenate([np.zeros(length.shape + (1,)), np.add.accumulate(kinks, axis=-1)], axis=-1)
    slope_start = y0[..., None] - w_over_h[..., None] * nodes[..., :-1] - drop_before
    slope_end = slope_start - w_over_h[..., None] * seg_len
    return seg_len, slope_start, slope_end


def stretched_lengths(seg_len, slope_start, slope_end):
    """L_e of every segment, ∫ (1 + y'^2)^(3/2) dx (Gauss–Legendre, see above)."""
    s = slope_start[..., None] + (slope_end - slope_start)[..., None] * _GL_T
    return seg_len * np.add.reduce(_GL_W * (1.0 + s * s) ** 1.5, axis=-1)


def irvine_lambda2(cable, tension, stretched_length=None):
    """Irvine's parameter λ² = (w l / H)² l EA / (H L_e) of the bare cable.

    Returns 0 when ``cable.EA`` is None (no sag-extensibility).
    """
    if cable.EA is None:
        return 0.0
    w, length = cable.weight_per_length, cable.length
    if stretched_length is None:
        e = w * length / (8 * tension)
        stretched_length = length * (1 + 8 * e * e)
    return (w * length / tension) ** 2 * length * cable.EA / (tension * stretched_length)


def sag_ratio(cable, tension) -> float:
    """Sag-to-span ratio e = w l / (8 H) of the bare cable."""
    return cable.weight_per_length * cable.length / (8.0 * tension)
