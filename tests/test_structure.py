"""Campbell's normal and parallel structure distributions (demstudy.analysis.structure).

Exact references: an uncorrelated (uniform random) gas gives the mean number density at every
distance in both distributions; a square lattice puts the parallel distribution's weight at
multiples of the lattice spacing and the normal distribution's at multiples of the row spacing.
Dimensionless particle units: d = 1.
"""

from __future__ import annotations

import numpy as np
import pytest

from demstudy.analysis.structure import StructureDistributions
from demstudy.io.frames import Frame


def frame(pos, lengths, t=0.0):
    n, dim = pos.shape
    return Frame(time=t, box_lo=np.zeros(dim), box_hi=np.asarray(lengths, float), position=pos,
                 velocity=np.zeros((n, dim)), angular_velocity=np.zeros((n, 1 if dim == 2 else 3)),
                 radius=np.full(n, 0.5))


@pytest.mark.parametrize("dim, n", [(2, 2000), (3, 4000)])
def test_uniform_gas_gives_the_number_density_in_both_distributions(dim, n):
    rng = np.random.default_rng(3)
    lengths = [20.0] * dim
    frames = [frame(rng.uniform(0, 20.0, (n, dim)), lengths, t) for t in range(24)]
    ana = StructureDistributions(dim=dim, r_max=4.0, dr=0.5).run(frames).finish()
    density = n / 20.0**dim
    for key in ("normal", "parallel"):
        value, err = ana.results[key], ana.results[f"{key}_err"]
        assert np.all(err > 0)
        assert np.all(np.abs(value - density) < 4 * err + 1e-3 * density), key


def test_square_lattice_peaks_at_the_spacings():
    """Rows 1.5 apart along y, particles 1.25 apart along x: the parallel distribution is
    non-zero only in the slices holding x-multiples of 1.25 (same row: |dy| = 0 < 1), the
    normal distribution only at multiples of 1.5, each with the exact lattice density."""
    ax, ay, nx, ny = 1.25, 1.5, 16, 14
    gx, gy = np.meshgrid((np.arange(nx) + 0.5) * ax, (np.arange(ny) + 0.5) * ay, indexing="ij")
    pos = np.stack([gx.ravel(), gy.ravel()], axis=1)
    lengths = [nx * ax, ny * ay]
    dr = 0.25
    ana = StructureDistributions(dim=2, r_max=6.0, dr=dr, half_width=0.9,
                                 y_mid=lengths[1] / 2).run([frame(pos, lengths)]).finish()
    r_lo = ana.results["r"] - dr / 2
    par, nor = ana.results["parallel"], ana.results["normal"]
    for k in range(len(r_lo)):
        hit_x = any(r_lo[k] <= m * ax < r_lo[k] + dr for m in range(1, 5))
        hit_y = any(r_lo[k] <= m * ay < r_lo[k] + dr for m in range(0, 5))
        # parallel: 2 partners (±m ax) per slice, area 2 dr · 2 half_width
        assert par[k] == pytest.approx(2 / (2 * dr * 1.8) if hit_x else 0.0)
        # normal: a full row of nx (two rows ±m ay, one at dy = 0 minus the particle itself)
        rows = 0 if not hit_y else (nx - 1 if r_lo[k] == 0 else 2 * nx)
        assert nor[k] == pytest.approx(rows / (2 * dr * lengths[0]))


def test_rejects_a_range_beyond_half_the_period():
    pos = np.random.default_rng(0).uniform(0, 6.0, (50, 2))
    with pytest.raises(ValueError, match="half the periodic length"):
        StructureDistributions(dim=2, r_max=4.0).run([frame(pos, [6.0, 6.0])])
