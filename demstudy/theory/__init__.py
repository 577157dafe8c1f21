"""Theory references for granular flows of hard discs and spheres (particle units d = 1,
m = 1; conventions in :mod:`demstudy.theory.kinetic`)."""

from __future__ import annotations

from demstudy._lazy import lazy_exports

# imported on first use (PEP 562): an engine run needs a few of these modules, and
# the others pull in scipy.integrate, scipy.special, scipy.spatial (~0.3 s, ~30 MiB)
_WHERE = {
    "CAMPBELL_A": "distributions",
    "CAMPBELL_DOF": "distributions",
    "campbell_reference": "distributions",
    "chi_density": "distributions",
    "corrected_s": "distributions",
    "malik_gaussian": "distributions",
    "savage_jeffrey": "distributions",
    "campbell_chi": "kinetic",
    "carnahan_starling_g0": "kinetic",
    "collision_frequency": "kinetic",
    "compressibility": "kinetic",
    "contact_value": "kinetic",
    "cooling_rate": "kinetic",
    "haff_t0": "kinetic",
    "haff_temperature": "kinetic",
    "henderson_g0": "kinetic",
    "mean_free_path": "kinetic",
    "mean_speed": "kinetic",
    "number_density": "kinetic",
    "pressure": "kinetic",
    "unit_volume": "kinetic",
    "NU_HEXAGONAL": "packing",
    "NU_SHEARABLE": "packing",
    "NU_SQUARE": "packing",
    "PHI_CUBIC": "packing",
    "mean_spacing": "packing",
    "nu_2d_from_3d": "packing",
    "nu_3d_from_2d": "packing",
}

__all__ = [
    "CAMPBELL_A",
    "CAMPBELL_DOF",
    "NU_HEXAGONAL",
    "NU_SHEARABLE",
    "NU_SQUARE",
    "PHI_CUBIC",
    "campbell_chi",
    "campbell_reference",
    "carnahan_starling_g0",
    "chi_density",
    "collision_frequency",
    "compressibility",
    "contact_value",
    "cooling_rate",
    "corrected_s",
    "haff_t0",
    "haff_temperature",
    "henderson_g0",
    "malik_gaussian",
    "mean_free_path",
    "mean_spacing",
    "mean_speed",
    "nu_2d_from_3d",
    "nu_3d_from_2d",
    "number_density",
    "pressure",
    "savage_jeffrey",
    "unit_volume",
]


__getattr__, __dir__ = lazy_exports(__name__, {k: f".{v}" for k, v in _WHERE.items()})
