"""Random cable configurations for cross-checks (seeded, reproducible)."""

import math

from stcs_ident.core.model import Attachment, Boundary, Cable


def random_end(rng, EI, length):
    kind = rng.integers(3)
    if kind == 0 or EI == 0:
        return Boundary.clamped()
    if kind == 1:
        return Boundary.pinned()
    return Boundary(EI / length * 10 ** rng.uniform(-1, 2))


def random_configuration(rng):
    """A cable, its attachments and tension, spanning the acceptance ranges:
    0–4 attachments with masses and springs, clamped / pinned / spring ends,
    λ² from 0 to 200, inclination 0–45°, ξ = l√(H/EI) from 3 to 1000."""
    length = rng.uniform(5, 150)
    m = 10 ** rng.uniform(-0.5, 2)
    theta = math.radians(rng.uniform(0, 45))
    g = 9.81
    w = m * g * math.cos(theta)
    e = rng.uniform(0.001, 0.04)  # sag ratio
    H = w * length / (8 * e)
    if rng.random() < 0.1:
        EI = 0.0
    else:
        xi = 10 ** rng.uniform(math.log10(3), 3)
        EI = H * length**2 / xi**2
    lam2 = 0.0 if rng.random() < 0.15 else rng.uniform(0, 200)
    Le = length * (1 + 8 * e * e)
    EA = None if lam2 == 0 else lam2 * H * Le / ((w * length / H) ** 2 * length)
    cable = Cable(length=length, mass_per_length=m, EI=EI, EA=EA, inclination=theta,
                  boundary_a=random_end(rng, EI, length), boundary_b=random_end(rng, EI, length))
    n_att = rng.integers(0, 5)
    positions = []
    while len(positions) < n_att:
        x = rng.uniform(0.05, 0.95) * length
        if all(abs(x - p) > 0.03 * length for p in positions):
            positions.append(x)
    atts = []
    for i, x in enumerate(sorted(positions)):
        mass = rng.uniform(0, 0.3) * m * length if rng.random() < 0.8 else 0.0
        spring = 10 ** rng.uniform(-1, 2) * H / length if rng.random() < 0.4 else 0.0
        atts.append(Attachment(f"A{i}", x, mass, spring))
    return cable, atts, H
