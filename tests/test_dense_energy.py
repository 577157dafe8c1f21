"""Dense soft contacts do not create energy (LAMMPS): the energy audit of dense 2D discs.

Dimensionless particle units: d = 1, m = 1, no gravity (the initial velocities, T = 1, or the
shear rate γ̇ = 1 set the time unit). Why: near jamming the soft β rule runs several times hotter
than the event-driven one (docs/stability.md, finding 2). These tests pin down that the heat is
not made by the contact model (history rotation, torque arm R − δ/2, time-step compensation):
total energy, spring energies included, never rises in free cooling, and in shear the energy
dissipated, W − ΔE, never decreases; the heat is shear work done on stiff enduring contacts.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from demstudy.engines.lammps.energy import audit
from demstudy.scene import validate_scene
from demstudy.stability.soft import packed_start, particle_file

FRACTION = 0.82  # near jamming, as in the dense-shear-2d stability row


def free_cooling_scene(folder, tangential: dict, kn: float):
    """224 discs on a jittered hexagonal lattice at ν = 0.82, T = 1, no shear, e = 1."""
    rng = np.random.default_rng(3)
    a = math.sqrt(math.pi / (2 * math.sqrt(3) * FRACTION))
    i, j = np.meshgrid(np.arange(14), np.arange(16), indexing="ij")
    pos = np.column_stack([(i + 0.5 * (j % 2) + 0.25).ravel() * a,
                           (j + 0.5).ravel() * a * math.sqrt(3) / 2])
    pos += rng.uniform(-1, 1, pos.shape) * (a - 1) / 4
    vel = rng.normal(size=pos.shape)
    vel -= vel.mean(axis=0)
    path = particle_file(folder, np.column_stack([pos, vel]).tolist())
    return validate_scene({
        "dimension": 2, "box": {"size": [14 * a, 16 * a * math.sqrt(3) / 2]},
        "particles": {"count": len(pos)},
        "contact": {"restitution": 1.0, "tangential": tangential},
        "initial": {"placement": "file", "path": path},
        "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 0.1},
        "soft": {"stiffness": kn}})


@pytest.mark.parametrize("tangential", [{"model": "smooth"}, {"model": "beta", "beta": 1.0},
                                        {"model": "beta", "beta": 0.0}])
def test_dense_elastic_free_cooling_never_gains_energy(tmp_path, tangential):
    """e = 1 and soft contacts (k_n = 1e3: 1.2-1.5 contacts per particle, multi-contact):
    kinetic + rotational + spring energy never rises by more than the integrator's round-off
    (measured: 2.7e-4 E0 smooth, 4.2e-4 rough β = 1). Rough contacts lose energy all the same
    although β = 1 is elastic for a binary collision: a contact that ends while the particle
    also touches others leaves with its spring stretched (≈ 60 % lost in one time unit)."""
    a = audit(free_cooling_scene(tmp_path, tangential, 1e3), tmp_path, 0.5)
    e = a.total
    rise = float(np.max(e - np.minimum.accumulate(e))) / e[0]
    assert rise < 1e-3
    assert np.mean(a.coordination) > 1.0  # enduring, multi-particle contacts
    if tangential["model"] == "smooth":
        assert e[-1] / e[0] > 0.999
    else:
        assert e[-1] / e[0] < 0.9


def test_dense_rough_shear_heat_is_shear_work(tmp_path):
    """Lees–Edwards shear at ν = 0.82, e = 0.7, β = 0, the automatic k_n: the dissipated
    energy W − ΔE never decreases (measured: largest dip 1e-6 W), while the shear stress is
    ~65 x that of smooth contacts (946 vs 14 in m/τ² per d over t in [0.5, 2]): the rough
    flow is shear-jammed in the elastic regime, its heat is work done on stiff contacts."""
    work = {}
    for name, tangential in {"smooth": {"model": "smooth"},
                             "rough": {"model": "beta", "beta": 0.0}}.items():
        folder = tmp_path / name
        folder.mkdir()
        size, path = packed_start(2, FRACTION, (14, 16), 7, folder)
        scene = validate_scene({
            "dimension": 2, "box": {"size": size}, "particles": {"count": 224},
            "contact": {"restitution": 0.7, "tangential": tangential},
            "shear": {"rate": 1.0}, "initial": {"placement": "file", "path": path},
            "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 0.1}})
        a = audit(scene, folder, 1.0)
        assert a.work[-1] > 0.0
        assert a.largest_gain() < 1e-4 * a.work[-1]
        late = a.time >= 0.5
        work[name] = a.work[-1]
        if name == "rough":
            assert np.mean(a.coordination[late]) > 2.5  # measured 3.2: a contact network
    assert work["rough"] > 10 * work["smooth"]  # measured 21 x over t <= 1
