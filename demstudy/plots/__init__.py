"""Figures from results files, one per kind, in the seed theses' forms (Campbell 1982,
Malik 2008). Dimensionless particle units: d = 1, m = 1, g = 1 with gravity.

Kinds (``demstudy plot RUN.h5 … --kind``; see docs/plots.md):

* ``profiles``: ν, u_x, T, rotational T against y, or (y − y_0)/H with ``scaled``;
* ``cgprofiles``: coarse-grained (Gaussian kernel) ν, u_x, T over the binned profiles
  (``scaled`` too);
* ``stress``: kinetic, contact / collisional and total P_xy, P_yy against y, wall stresses,
  momentum balance;
* ``vdf``: Campbell's P(X1…X5) with folded Maxwellians, Malik's P(C/σ) with the Gaussian;
* ``angles``: P(θ) in both conventions with Savage–Jeffrey;
* ``freepath``: P(λ), P(τ) per y-bin with the exponential of the bin's mean;
* ``gr``: g(r) (whole box, in-bin when stored);
* ``structure``: Campbell's normal and parallel structure distributions with the mean
  number density;
* ``vcorr``: C_αα(r) per component and the off-diagonal C_αβ(r);
* ``lambda``: Λ(y) with 1/3;
* ``waves``: power spectrum of the dominant plane, its density contour, mode amplitudes;
* ``cooling``: homogeneous cooling runs only, T(t)/T0 with Haff's law (log–log);
* ``health``: soft-contact runs only, overlaps and coordination per sample with the limits
  of the hard-particle verdict (:data:`demstudy.contact.health.LIMITS`).

Every ``draw_<kind>(runs, …)`` returns a :class:`matplotlib.figure.Figure` (Agg canvas, no
pyplot); :func:`plot_files` loads files, skips kinds a file lacks with a one-line notice and
writes the PNGs. The kinds (:mod:`.kinds`) need no matplotlib; the drawing functions
(:mod:`.figures`) load on first use, so that the command line's help costs no matplotlib.
"""

from __future__ import annotations

from .._lazy import lazy_exports
from .kinds import KINDS, SCALED, parse_kinds

__all__ = ["KINDS", "SCALED", "Run", "draw", "draw_angles", "draw_cgprofiles", "draw_cooling",
           "draw_eos", "draw_freepath", "draw_gr", "draw_health", "draw_lambda", "draw_profiles",
           "draw_stress", "draw_structure", "draw_vcorr", "draw_vdf", "draw_waves",
           "output_path", "parse_kinds", "plot_files", "plot_profiles", "reference_height"]


# the drawing functions, imported with matplotlib on first use
__getattr__, __dir__ = lazy_exports(__name__, {
    name: ".figures" for name in [*__all__, "DRAW"] if name not in ("KINDS", "SCALED",
                                                                     "parse_kinds")})
