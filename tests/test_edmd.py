"""Event-driven hard-particle engine (``--engine edmd``), milestone 1.

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim), T0 = 1 sets the time scale.
Reference formulas (stated here because the assertions depend on them):

* pair collision, equal masses: ΔE = −(m/4)[(1 − e²) g_n² + K/(1 + K)(1 − β²)|g_t|²];
* Carnahan–Starling Z = (1 + φ + φ² − φ³)/(1 − φ)³ (3D), Henderson Z = (1 + ν²/8)/(1 − ν)² (2D);
* contact values g0 = (1 − φ/2)/(1 − φ)³ (CS), (1 − 7ν/16)/(1 − ν)² (Henderson);
* Enskog collision frequency per particle ω = 4 n d² g0 √(πT/m) (3D), 2 n d g0 √(πT/m) (2D);
* Haff: dT/dt = −(1 − e²) ω T / d_f (smooth particles, d_f = dim translational degrees of
  freedom, one collision per pair loses (1 − e²) T on average), so T = T0/(1 + t/t0)² with
  t0 = 2 d_f / ((1 − e²) ω0), ω0 the Enskog frequency at T0.

Runtime about a minute on a 2-core machine (the elastic drift tests take most of it).
"""

from __future__ import annotations

import dataclasses
import math
import platform
from pathlib import Path

import numpy as np
import pytest
from edmd_helpers import (
    ENGINE_SCENE,
    assert_same_particles,
    energy,
    engine_scene,
    make_scene,
    resumed,
    system,
    whole_and_resumed,
)
from scipy.spatial import cKDTree

from demstudy.analysis.suite import profile_analysis
from demstudy.engines import get_backend
from demstudy.engines.edmd import (
    EdmdBackend,
    EventDriven,
    collide_pair,
    from_initial_state,
)
from demstudy.errors import UnsupportedByEngine
from demstudy.io.results import read_results
from demstudy.scene.initial import build_initial_state
from demstudy.simulation import RunOptions, run_scene
from demstudy.simulation.checkpoint import pickle_atomically
from demstudy.theory import kinetic as theory


def fraction(scene) -> float:
    return scene.solid_fraction




# ---- collision rules ----------------------------------------------------------------------

def random_pair(rng, dim):
    n = rng.normal(size=3)
    if dim == 2:
        n[2] = 0.0
    n /= np.linalg.norm(n)
    vi, vj = rng.normal(size=3), rng.normal(size=3)
    wi, wj = rng.normal(size=3), rng.normal(size=3)
    if dim == 2:
        vi[2] = vj[2] = 0.0
        wi[:2] = wj[:2] = 0.0
    # make the pair approach (centre velocities)
    if (vi - vj) @ n < 0:
        vi, vj = vj, vi
    return n, vi, vj, wi, wj


def pair_energy(m, ri, rj, K, vi, vj, wi, wj, mj=None):
    mj = m if mj is None else mj
    return 0.5 * (m * vi @ vi + mj * vj @ vj + K * m * ri**2 * wi @ wi
                  + K * mj * rj**2 * wj @ wj)


def contact_velocity(n, ri, rj, vi, vj, wi, wj):
    return vi - vj + np.cross(ri * wi + rj * wj, n)


@pytest.mark.parametrize("dim", [2, 3])
def test_energy_loss_per_collision_matches_the_analytic_formula(dim):
    rng = np.random.default_rng(7 + dim)
    for _ in range(500):
        n, vi, vj, wi, wj = random_pair(rng, dim)
        m = rng.uniform(0.2, 3.0)
        ri, rj = rng.uniform(0.3, 0.7, size=2)  # ΔE does not depend on the radii
        e, beta, K = rng.uniform(0.05, 1.0), rng.uniform(-1, 1), rng.uniform(0.05, 1.0)
        g = contact_velocity(n, ri, rj, vi, vj, wi, wj)
        gn = g @ n
        gt = g - gn * n
        before = pair_energy(m, ri, rj, K, vi, vj, wi, wj)
        vi2, vj2, wi2, wj2, J = collide_pair(n, ri, rj, m, m, K, e, beta, vi, vj, wi, wj)
        after = pair_energy(m, ri, rj, K, vi2, vj2, wi2, wj2)
        expected = -(m / 4) * ((1 - e**2) * gn**2 + K / (1 + K) * (1 - beta**2) * gt @ gt)
        assert after - before == pytest.approx(expected, rel=1e-11, abs=1e-13 * before)
        g2 = contact_velocity(n, ri, rj, vi2, vj2, wi2, wj2)
        np.testing.assert_allclose(g2 @ n, -e * gn, atol=1e-13 * (1 + abs(gn)))
        np.testing.assert_allclose(g2 - (g2 @ n) * n, -beta * gt, atol=1e-12)
        np.testing.assert_allclose(m * (vi2 + vj2), m * (vi + vj), atol=1e-12)
        np.testing.assert_allclose(vi2, vi + J / m, atol=1e-13)
        if dim == 2:
            assert vi2[2] == vj2[2] == 0.0 and not wi2[:2].any() and not wj2[:2].any()


def test_unequal_masses_follow_the_reduced_mass_form():
    rng = np.random.default_rng(3)
    for _ in range(200):
        n, vi, vj, wi, wj = random_pair(rng, 3)
        mi, mj = rng.uniform(0.2, 3.0, size=2)
        ri, rj = rng.uniform(0.3, 0.7, size=2)
        e, beta, K = rng.uniform(0.05, 1.0), rng.uniform(-1, 1), rng.uniform(0.05, 1.0)
        g = contact_velocity(n, ri, rj, vi, vj, wi, wj)
        gn = g @ n
        gt = g - gn * n
        before = pair_energy(mi, ri, rj, K, vi, vj, wi, wj, mj)
        vi2, vj2, wi2, wj2, _ = collide_pair(n, ri, rj, mi, mj, K, e, beta, vi, vj, wi, wj)
        after = pair_energy(mi, ri, rj, K, vi2, vj2, wi2, wj2, mj)
        meff = mi * mj / (mi + mj)
        expected = -(meff / 2) * ((1 - e**2) * gn**2 + K / (1 + K) * (1 - beta**2) * gt @ gt)
        assert after - before == pytest.approx(expected, rel=1e-11, abs=1e-13 * before)
        np.testing.assert_allclose(mi * vi2 + mj * vj2, mi * vi + mj * vj, atol=1e-12)
        # angular momentum about the contact point is conserved
        ci, cj = ri * n, -rj * n  # contact point relative to each centre
        li = K * mi * ri**2 * wi - np.cross(ci, mi * vi)
        lj = K * mj * rj**2 * wj - np.cross(cj, mj * vj)
        li2 = K * mi * ri**2 * wi2 - np.cross(ci, mi * vi2)
        lj2 = K * mj * rj**2 * wj2 - np.cross(cj, mj * vj2)
        np.testing.assert_allclose(li2, li, atol=1e-12)
        np.testing.assert_allclose(lj2, lj, atol=1e-12)


def test_smooth_collisions_leave_spins_and_elastic_rough_ones_conserve_energy():
    rng = np.random.default_rng(11)
    for dim in (2, 3):
        for _ in range(100):
            n, vi, vj, wi, wj = random_pair(rng, dim)
            _, _, wi2, wj2, _ = collide_pair(n, 0.5, 0.5, 1.0, 1.0, 0.4, 0.7, -1.0,
                                             vi, vj, wi, wj)
            assert np.array_equal(wi2, wi) and np.array_equal(wj2, wj)
            before = pair_energy(1.0, 0.5, 0.5, 0.4, vi, vj, wi, wj)
            out = collide_pair(n, 0.5, 0.5, 1.0, 1.0, 0.4, 1.0, 1.0, vi, vj, wi, wj)
            after = pair_energy(1.0, 0.5, 0.5, 0.4, *out[:4])
            assert after == pytest.approx(before, rel=1e-14)


# ---- conservation and overlaps -------------------------------------------------------------

@pytest.mark.parametrize("dim", [3, 2])
def test_elastic_gas_conserves_energy_over_1e7_collisions(dim):
    """The issue's hard case 1: number density 0.5 (3D: φ = 0.26; 2D: ν = 0.39), N = 4000,
    1e7 collisions (about 30 s each on the 2-core development machine): relative energy
    drift < 1e-10 at every check, momentum conserved to round-off, no overlap."""
    n = 4000
    phi = 0.5 * (math.pi / 6 if dim == 3 else math.pi / 4)
    s = system(make_scene(dim, phi, n, seed=5))
    e0 = energy(s)
    p0 = s.velocities().sum(axis=0)
    t, drift = 0.0, 0.0
    while s.collisions < 10_000_000:
        t += 20.0
        s.advance_to(t, stop_collisions=10_000_000)
        drift = max(drift, abs(energy(s) - e0) / e0)
        assert drift < 1e-10
    assert s.collisions == 10_000_000
    p = s.velocities().sum(axis=0)
    assert np.abs(p - p0).max() < 1e-10 * math.sqrt(n)
    assert s.min_gap() > -1e-9


def test_elastic_rough_polydisperse_gas_conserves_energy():
    scene = make_scene(3, 0.3, 1500, seed=2, spread=0.4, tangential="1.0")
    s = system(scene)
    state = build_initial_state(scene)
    mass = state.mass
    e0 = energy(s)
    s.advance_to(8.0)
    assert s.collisions > 5e4
    assert abs(energy(s) - e0) / e0 < 1e-12
    assert s.rotational_energy > 0.1 * e0  # spins took energy (β = 1 couples them)
    np.testing.assert_allclose((mass[:, None] * s.velocities()).sum(axis=0),
                               (mass[:, None] * state.velocity).sum(axis=0), atol=1e-10)
    assert s.min_gap() > -1e-9


def test_dissipated_energy_is_booked():
    s = system(make_scene(2, 0.3, 1000, seed=4, e=0.8, tangential="0.3"), tc=1e-5)
    e0 = energy(s)
    s.advance_to(5.0)
    assert s.dissipated > 0.3 * e0
    assert energy(s) + s.dissipated == pytest.approx(e0, rel=1e-11)


def pair_gaps(positions, diameters, box):
    tree = cKDTree(positions, boxsize=box)
    pairs = tree.query_pairs(1.5 * diameters.max(), output_type="ndarray")
    d = positions[pairs[:, 0]] - positions[pairs[:, 1]]
    d -= np.round(d / box) * box
    return np.linalg.norm(d, axis=1) - (diameters[pairs[:, 0]] + diameters[pairs[:, 1]]) / 2


@pytest.mark.parametrize("dim, phi, n, t_end", [(3, 0.55, 864, 8.0), (2, 0.80, 1000, 4.0)])
def test_dense_packings_never_overlap(dim, phi, n, t_end):
    """Dense random starts (demstudy's jittered close-packed lattice subset)."""
    scene = make_scene(dim, phi, n, seed=3)
    assert scene.solid_fraction == pytest.approx(phi, rel=1e-6)
    state = build_initial_state(scene)
    s = system(scene)
    box = np.asarray(scene.box.size)
    worst = 0.0
    for k in range(1, 41):
        s.advance_to(k * t_end / 40)
        gaps = pair_gaps(s.positions(), state.diameter, box)
        worst = min(worst, gaps.min(), s.min_gap())
    assert worst > -1e-9
    assert s.collisions > 8e4
    assert abs(energy(s) / (state.mass[:, None] * state.velocity**2).sum() * 2 - 1) < 1e-10


def test_inelastic_collapse_is_prevented_by_the_tc_model():
    """Dense 2D cooling with e = 0.5: with t_c = 1e-5 the time reaches t = 200 within 3e6
    events (measured: about 1e6); T falls by orders of magnitude meanwhile."""
    scene = make_scene(2, 0.5, 500, seed=9, e=0.5)
    s = system(scene, tc=1e-5)
    e0 = energy(s)
    assert s.advance_to(200.0, max_events=3_000_000)
    assert s.time == 200.0
    assert energy(s) < 1e-2 * e0
    assert s.elastic_tc_collisions > 0
    assert s.min_gap() > -1e-9


# ---- equilibrium statistics ----------------------------------------------------------------

def block_measure(s: EventDriven, n_blocks: int, block_time: float, dim: int):
    """Per block: compressibility factor Z = PV/(NT) and collision frequency per particle."""
    n = s.n
    z, freq = [], []
    w0, c0, t = s.virial, s.collisions, s.time
    for _ in range(n_blocks):
        t += block_time
        s.advance_to(t)
        kinetic = s.kinetic_energy
        temperature = 2 * kinetic / (dim * (n - 1))  # zero total momentum: dim (N − 1) dofs
        z.append((2 * kinetic / dim + (s.virial - w0) / (dim * block_time))
                 / (n * temperature))
        freq.append(2 * (s.collisions - c0) / (n * block_time))
        w0, c0 = s.virial, s.collisions
    z, freq = np.array(z), np.array(freq)
    return (z.mean(), z.std(ddof=1) / math.sqrt(n_blocks), freq.mean(),
            freq.std(ddof=1) / math.sqrt(n_blocks), temperature)


def equilibrated(dim, phi, n, seed=1):
    scene = make_scene(dim, phi, n, seed=seed)
    s = system(scene)
    s.advance_to(10.0)
    return s, scene


def collisions_per_time(s, dim, phi, n):
    """Enskog estimate (CS/Henderson g0) of the collisions per unit time, T = 1."""
    density = n / (s.n / fraction_density(dim, phi))
    return n / 2 * enskog_frequency(dim, phi, density, 1.0)


def fraction_density(dim, phi):
    return float(theory.number_density(phi, dim))


def enskog_frequency(dim, phi, density, temperature):
    """Enskog collisions per particle and time at number density ``density`` (the contact
    value from φ: Carnahan–Starling / Henderson)."""
    return float(theory.collision_frequency(phi, temperature, dim)) * density / fraction_density(
        dim, phi)


def equation_of_state(dim, phi):
    """Carnahan–Starling (3D), Henderson (2D): Z = 1 + 2^(dim−1) φ g0."""
    return float(theory.compressibility(phi, dim))


def accurate_equation_of_state(dim, phi):
    """Closer fits to simulation data: Kolafa–Labík–Malijevský (3D; CS is ~0.3 % low at
    φ = 0.3–0.45) and Luding's corrected Henderson (2D; Henderson is 1–2 % high at ν ≥ 0.6)."""
    if dim == 3:
        return (1 + phi + phi**2 - 2 / 3 * (phi**3 + phi**4)) / (1 - phi) ** 3
    return (1 + phi**2 / 8) / (1 - phi) ** 2 - phi**4 / (64 * (1 - phi) ** 4)


@pytest.mark.parametrize("dim, phi", [(3, 0.1), (3, 0.25), (3, 0.4), (3, 0.45), (2, 0.2),
                                      (2, 0.3), (2, 0.4), (2, 0.6)])
def test_pressure_matches_the_equation_of_state(dim, phi):
    """≈ 1e6 collisions per state point in 20 blocks; the block-averaged standard error of Z
    is asserted < 0.15 % so a 0.5 % deviation is resolved. Henderson itself is off by more
    than 0.5 % above ν ≈ 0.5 (measured with 4e6 collisions: −0.42 % at 0.5, −2.2 % at 0.65),
    so ν = 0.6 (2e6 collisions: slower fluctuations near the fluid–hexatic transition) is
    checked against the corrected form only."""
    n = 2000
    s, scene = equilibrated(dim, phi, n)
    phi = scene.solid_fraction
    per_time = n / 2 * enskog_frequency(dim, phi, fraction_density(dim, phi), 1.0)
    block = (2e6 if phi > 0.55 else 1e6) / 20 / per_time
    z, z_err, *_ = block_measure(s, 20, block, dim)
    assert z_err / z < 1.5e-3
    if dim == 3 or phi < 0.45:
        assert z / equation_of_state(dim, phi) - 1 == pytest.approx(0.0, abs=5e-3)
    assert z / accurate_equation_of_state(dim, phi) - 1 == pytest.approx(0.0, abs=3e-3)


def test_collision_frequency_matches_enskog_at_phi_0_2():
    n, dim = 4000, 3
    s, scene = equilibrated(dim, 0.2, n, seed=2)
    phi = scene.solid_fraction
    per_time = n / 2 * enskog_frequency(dim, phi, fraction_density(dim, phi), 1.0)
    _, _, freq, freq_err, temperature = block_measure(s, 20, 2e6 / 20 / per_time, dim)
    expected = enskog_frequency(dim, phi, fraction_density(dim, phi), temperature)
    assert freq_err / freq < 2e-3
    assert freq / expected - 1 == pytest.approx(0.0, abs=1e-2)


@pytest.mark.parametrize("dim", [3, 2])
def test_haff_law_for_a_dilute_inelastic_smooth_gas(dim):
    """φ (ν) = 0.05, e = 0.9, N = 2000, T0 = 1, averaged over 16 seeds, up to t = 2 t0 with
    t0 = 2 d_f / ((1 − e²) ω0), ω0 the Enskog frequency (CS / Henderson g0): 3D t0 = 41.0,
    2D t0 = 86.1. Measured T/T_Haff at t = (0.5, 1, 1.5, 2) t0: 3D 1.003, 1.005, 1.007, 1.008
    (± 0.003), 2D 1.010, 1.018, 1.021, 1.021 (± 0.005): the homogeneous cooling state cools
    slightly slower than Enskog–Haff (a2 < 0, velocity correlations; larger 2D systems drift
    to +3 % at 2 t0), so the 3 % bound is checked up to 2 t0 with N = 2000."""
    e, phi, n = 0.9, 0.05, 2000
    scene = make_scene(dim, phi, n, seed=1, e=e)
    phi = scene.solid_fraction
    omega0 = enskog_frequency(dim, phi, fraction_density(dim, phi), 1.0)
    t0 = 2 * dim / ((1 - e**2) * omega0)
    assert t0 == pytest.approx({3: 41.0, 2: 86.1}[dim], abs=0.1)
    times = t0 * np.array([0.25, 0.5, 1.0, 1.5, 2.0])
    haff = 1 / (1 + times / t0) ** 2
    ratios = []
    for seed in range(1, 17):
        s = system(make_scene(dim, phi, n, seed=seed, e=e), tc=1e-5)
        t_init = 2 * s.kinetic_energy / (dim * (n - 1))
        row = []
        for t in times:
            s.advance_to(t)
            row.append(2 * s.kinetic_energy / (dim * (n - 1)) / t_init)
        ratios.append(np.array(row) / haff)
    ratios = np.array(ratios)
    error = ratios.std(axis=0, ddof=1) / math.sqrt(len(ratios))
    assert np.all(error < 0.01)  # resolves the 3 % bound
    assert np.all(haff[-1] * ratios[:, -1] < 0.15)  # it really cooled: T(2 t0) ≈ T0/9
    np.testing.assert_allclose(ratios.mean(axis=0), 1.0, atol=0.03)


# ---- determinism, checkpoints --------------------------------------------------------------

def test_state_round_trip_continues_bit_identically():
    scene = make_scene(3, 0.3, 500, seed=6, e=0.9, tangential="0.2")
    a = system(scene, tc=1e-5)
    a.advance_to(3.0)
    saved = a.get_state()
    a.advance_to(6.0)
    b = resumed(scene, saved, 3.0, 6.0)
    assert_same_particles(a, b)
    assert (a.collisions, a.virial, a.dissipated) == (b.collisions, b.virial, b.dissipated)


def test_a_rejected_state_leaves_the_engine_as_it_was():
    """set_state checks everything before it changes anything: after each corrupt state is
    refused, the engine holds the same state and continues exactly as an untouched twin."""
    scene = make_scene(2, 0.4, 300, seed=2, e=0.9)
    donor = system(scene, tc=1e-5)
    donor.advance_to(2.0)
    good = donor.get_state()

    def corrupt(change):
        state = {k: np.array(v, copy=True) for k, v in good.items()}
        change(state)
        return state

    def new_box_bad_order(s):  # another x period (re-grids) and then a corrupt order
        s["scalars"][3] *= 3.0
        s["order"][1] = s["order"][0]

    def set_(key, index, value):
        def change(s):
            s[key].reshape(-1)[index] = value
        return change

    cases = {
        "order is not a permutation": new_box_bad_order,
        "non-finite position": set_("pos", 5, np.nan),
        "stress bins": set_("scalars", 35, -1.0),
        "non-finite scalar": set_("scalars", 7, np.inf),
        "Lees-Edwards cell offset": set_("scalars", 5, 1e6),
        "invalid scheduled event": set_("ev_partner", 3, -7),  # the lower wall: there is none
        "invalid time of the last collision": set_("last", 0, np.inf),
    }
    a, twin = system(scene, tc=1e-5), system(scene, tc=1e-5)
    a.advance_to(1.0)
    twin.advance_to(1.0)
    before, cells = a.get_state(), a.cells
    for message, change in cases.items():
        with pytest.raises(ValueError, match=message):
            a.set_state(corrupt(change))
        after = a.get_state()
        assert all(np.array_equal(after[k], before[k]) for k in before), message
        assert a.cells == cells
    a.advance_to(3.0)
    twin.advance_to(3.0)
    assert_same_particles(a, twin)
    assert (a.collisions, a.virial) == (twin.collisions, twin.virial)


HAS_AVX2 = platform.machine() == "x86_64" and "avx2" in Path("/proc/cpuinfo").read_text()


@pytest.mark.parametrize("dim, options", [
    (3, {}),
    (3, {"shear_rate": 1.0}),
    (3, {"gravity": [0.3, 0.0, -0.2]}),  # the parabolic extrapolation of the candidates
    (2, {}),
])
def test_simd_pair_times_give_the_scalar_bits(dim, options):
    """The AVX2 pair-time kernel does the scalar code's operations in the same order: whole
    runs (with spread sizes, inelastic, rough) are bit-identical with and without it."""
    from demstudy._native import edmd_set_simd

    scene = make_scene(dim, 0.35, 3000 if dim == 3 else 1500, seed=3, e=0.9, spread=0.2,
                       tangential="0.3")
    runs = []
    try:
        for simd in (True, False):
            used = edmd_set_simd(simd)
            assert used == (simd and HAS_AVX2)
            s = system(scene, tc=1e-5, **options)
            s.advance_to(1e9, max_events=60_000)
            runs.append((s.positions(), s.velocities(), s.angular_velocities(), s.collisions,
                         s.virial, s.time))
    finally:
        edmd_set_simd(True)
    for a, b in zip(*runs, strict=True):
        assert np.array_equal(a, b)
    assert runs[0][3] > 20_000  # many collisions, most through the interior cells' kernel


def test_rejects_bad_input():
    scene = make_scene(3, 0.2, 100)
    st = build_initial_state(scene)
    with pytest.raises(ValueError, match="at least 3 largest particle diameters .axis 0: 2.5"):
        from_initial_state(st, [2.5, 2.5, 2.5])
    with pytest.raises(ValueError, match="restitution"):
        from_initial_state(st, scene.box.size, e=1.5)
    with pytest.raises(ValueError, match="shear_rate must be finite and >= 0"):
        from_initial_state(st, scene.box.size, shear_rate=-1.0)  # time would run backwards
    with pytest.raises(ValueError, match="stress bins of finite positive width"):
        from_initial_state(st, scene.box.size, stress_bins=[0.0, 0.0, 4])
    with pytest.raises(ValueError, match="stress bins of finite positive width"):
        from_initial_state(st, scene.box.size, stress_bins=[0.0, 1.0, 2.0**61])  # 9 n wraps
    # a box far too large for its particles: its long axes are coarsened (counted without
    # overflow) while the short one keeps its cells, and it runs
    huge = from_initial_state(st, [2.0**30, 2.0**30, 16.0])
    huge.advance_to(0.5)
    bad = dataclasses.replace(st, angular_velocity=np.full_like(st.angular_velocity, np.nan))
    with pytest.raises(ValueError, match="non-finite angular velocity"):
        from_initial_state(bad, scene.box.size)
    s = from_initial_state(st, scene.box.size)
    s.advance_to(1.0)
    with pytest.raises(ValueError, match="must not decrease"):
        s.advance_to(0.5)


# ---- the engine ------------------------------------------------------------------------------



def test_engine_writes_the_common_results_file(tmp_path):
    assert get_backend("edmd") is EdmdBackend
    scene = engine_scene()
    path = run_scene(scene, "edmd", RunOptions(out=tmp_path / "r.h5", progress=False,
                                              keep_frames=True))
    res = read_results(path)
    assert res.attrs["engine"] == "edmd" and res.attrs["seed"] == 3
    assert res.attrs["equilibration_end"] == 2.0
    assert "kinetic_energy_trend" in res.attrs and "steady" in res.attrs
    ts = res.timeseries
    np.testing.assert_allclose(ts["time"], np.arange(13) * 0.5)
    for key in ("kinetic_energy", "rotational_energy", "momentum", "collisions", "pressure"):
        assert key in ts
    assert ts["momentum"].shape == (13, 2)
    assert np.isnan(ts["pressure"][0]) and np.all(ts["pressure"][1:] > 0)
    assert np.all(np.diff(ts["collisions"]) > 0)
    assert res.profiles["solid_fraction"].mean() == pytest.approx(0.3, rel=0.02)
    assert res.profile_attrs["samples"] == 8
    assert res.frames["position"].shape[0] == 8
    assert res.frames["angular_velocity"].shape[2] == 1
    np.testing.assert_array_equal(res.frames["box_hi"][0], scene.box.size)
    # the stored frames feed the common analyses (demstudy analyze)
    from demstudy.io.results import frames_of
    again = profile_analysis(scene).run(frames_of(res, 2)).finish()
    np.testing.assert_allclose(again.results["solid_fraction"], res.profiles["solid_fraction"])
    assert not (tmp_path / "r.edmd").exists()


def test_engine_resume_is_bit_identical(tmp_path):
    scene = engine_scene()
    a, b = whole_and_resumed(scene, tmp_path)
    for key, value in a.timeseries.items():
        assert np.array_equal(value, b.timeseries[key], equal_nan=True), key
    for key, value in a.profiles.items():
        assert np.array_equal(value, b.profiles[key], equal_nan=True), key


@pytest.mark.parametrize("overrides, field", [
    ({"box.periodic": ["x"], "gravity": {"angle": 20.0},
      "walls": [{"side": "lower", "restitution": 0.9, "kind": "bumpy",
                 "bumps": {"spacing": 1.0}}]}, "walls[lower].bumps.pattern"),
    ({"contact.law": {"model": "campbell-exp"}}, "contact.law.model"),  # needs g for √(gR)
    ({"box.size": [20.0, 2.5]}, "box.size"),
    ({"measure.axis": "x", "measure.statistics": ["profiles", "stress"]}, "measure.axis"),
])
def test_engine_refuses_what_it_cannot_do(overrides, field, tmp_path):
    """Regular bumpy walls under gravity (the bottom layer cages itself at zero gaps),
    Campbell's e(v) without gravity and periodic boxes too small for the cell lists are
    refused before anything runs, naming the field."""
    scene = engine_scene(overrides)
    with pytest.raises(UnsupportedByEngine) as info:
        run_scene(scene, "edmd", RunOptions(out=tmp_path / "x.h5", progress=False))
    assert info.value.engine == "edmd" and info.value.field_name == field
    assert not (tmp_path / "x.h5").exists()


def test_resume_refuses_checkpoints_it_cannot_continue(tmp_path):
    """A checkpoint continues only with the engine version that wrote it, whole, and with
    frames kept as at the start; a fresh run must not delete another output's checkpoint
    in the work folder they share (names that differ only in the suffix)."""
    import pickle

    from demstudy.errors import EngineError

    scene = engine_scene({"run.production": 1.0})
    out = tmp_path / "r.v1"
    with pytest.raises(EngineError, match="--resume"):
        run_scene(scene, "edmd", RunOptions(out=out, progress=False, wall_limit=0.0))
    ckpt = tmp_path / "r.edmd" / "checkpoint.pkl"
    saved = pickle.loads(ckpt.read_bytes())
    assert saved["version"].endswith(EdmdBackend.version) and "diameter d = 1" in saved["units"]

    def resume(**kw):
        return run_scene(scene, "edmd", RunOptions(out=out, progress=False, resume=True, **kw))

    with pytest.raises(EngineError, match="keep-frames"):
        resume(keep_frames=True)
    with pytest.raises(EngineError, match=r"run.production: 1.0 in the checkpoint, 2.0 now"):
        run_scene(engine_scene({"run.production": 2.0}), "edmd",
                         RunOptions(out=out, progress=False, resume=True))
    with pytest.raises(EngineError, match="checkpoint of the interrupted run writing .*r.v1"):
        run_scene(scene, "edmd", RunOptions(out=tmp_path / "r.v2", progress=False))
    intact = ckpt.read_bytes()
    pickle_atomically(ckpt, {**saved, "version": "demstudy-edmd 0.0"})
    with pytest.raises(EngineError, match="written by demstudy-edmd 0.0"):
        resume()
    ckpt.write_bytes(intact[:1000])
    with pytest.raises(EngineError, match="is damaged"):
        resume()
    pickle_atomically(ckpt, [1, 2])  # whole, but not a checkpoint
    with pytest.raises(EngineError, match="not a checkpoint of the edmd engine"):
        resume()
    ckpt.write_bytes(intact)
    assert read_results(resume()).attrs["engine"] == "edmd"  # the intact one continues


@pytest.mark.parametrize("where", [0.1, 0.5, 0.9, 0.99])
def test_resume_refuses_a_checkpoint_with_flipped_bytes(tmp_path, where):
    """Bytes flipped anywhere in the state pickle (unpickled, flips resumed runs with T of
    1e178): --resume refuses the checkpoint by name before unpickling it and writes nothing;
    the work folder is left as it was."""
    from demstudy.errors import EngineError

    scene = engine_scene({"run.production": 1.0})
    out = tmp_path / "r.h5"
    with pytest.raises(EngineError, match="--resume"):
        run_scene(scene, "edmd", RunOptions(out=out, progress=False, wall_limit=0.0))
    ckpt = tmp_path / "r.edmd" / "checkpoint.pkl"
    data = bytearray(ckpt.read_bytes())
    at = int(where * len(data))
    data[at:at + 4] = bytes(b ^ 0xFF for b in data[at:at + 4])
    ckpt.write_bytes(bytes(data))
    before = sorted((p.name, p.stat().st_mtime_ns) for p in ckpt.parent.iterdir())
    with pytest.raises(EngineError) as info:
        run_scene(scene, "edmd", RunOptions(out=out, progress=False, resume=True))
    assert str(info.value) == (f"--resume: checkpoint {ckpt} is damaged (checksum mismatch); "
                               "remove the work folder to start afresh")
    assert not out.exists()
    assert sorted((p.name, p.stat().st_mtime_ns) for p in ckpt.parent.iterdir()) == before


def test_a_stop_inside_a_sample_interval_resumes_bit_identically(tmp_path, monkeypatch):
    """Ctrl-C or the wall-clock limit is honoured between two event chunks, not only at the
    next sample: the run checkpoints mid-interval and the resumed run, its chunks starting
    where the stopped one ended, gives the same results bit for bit. Chunks of 50 events
    here (10^7 in production) so that an interval holds several."""
    import pickle

    from demstudy.engines.edmd import core
    from demstudy.errors import EngineError

    monkeypatch.setattr(core, "STALL_CHUNK", 50)
    scene = engine_scene({"run.equilibration": 0.5, "run.production": 1.0})
    whole = read_results(run_scene(scene, "edmd", RunOptions(out=tmp_path / "whole.h5",
                                                            progress=False)))
    out = tmp_path / "parts.h5"
    ckpt = tmp_path / "parts.edmd" / "checkpoint.pkl"
    times, inside = [], 0
    for k in range(4):  # each part stops after its first chunk (or at a sample reached first)
        with pytest.raises(EngineError, match="after a checkpoint") as stopped:
            run_scene(scene, "edmd", RunOptions(out=out, progress=False, resume=k > 0,
                                               wall_limit=0.0))
        saved = pickle.loads(ckpt.read_bytes())
        times.append(saved["backend"]["core"]["scalars"][0])
        if "inside a sample interval" in str(stopped.value):
            inside += 1
            assert saved["run"].samples * 0.5 < times[-1] < (saved["run"].samples + 1) * 0.5
    assert inside >= 2 and times == sorted(set(times))
    parts = read_results(run_scene(scene, "edmd", RunOptions(out=out, progress=False,
                                                            resume=True)))
    for key, value in whole.timeseries.items():
        assert np.array_equal(value, parts.timeseries[key], equal_nan=True), key
    for key, value in whole.profiles.items():
        assert np.array_equal(value, parts.profiles[key], equal_nan=True), key


def test_lees_edwards_tilt_follows_the_results_convention(tmp_path):
    """The recorded tilt (timeseries and frames) is the image offset γ̇ L_y t flipped into
    [−L_x/2, L_x/2), as LAMMPS writes it (``flip yes``)."""
    scene = engine_scene({"shear": {"rate": 0.3}, "run.equilibration": 0.0,
                          "run.production": 6.0})
    res = read_results(run_scene(scene, "edmd", RunOptions(out=tmp_path / "le.h5",
                                                          progress=False, keep_frames=True)))
    lx, ly = scene.box.size
    t, tilt = res.timeseries["time"], res.timeseries["tilt"]
    assert np.all((tilt >= -lx / 2) & (tilt < lx / 2))
    drift = np.mod(tilt - 0.3 * ly * t + lx / 2, lx) - lx / 2
    np.testing.assert_allclose(drift, 0.0, atol=1e-9)
    assert tilt.min() < -lx / 4 and tilt.max() > lx / 4  # flipped at least once
    np.testing.assert_array_equal(res.frames["tilt"], tilt[-len(res.frames["tilt"]):])


def test_a_collision_count_that_cannot_be_reached_is_an_error(tmp_path):
    """run.unit = 'collisions' with particles at rest: no event is left, so the first sample's
    count can never be reached; the run says so instead of writing times of 1e300."""
    from demstudy.errors import EngineError

    scene = engine_scene({"run.unit": "collisions", "run.equilibration": 0.0,
                          "run.production": 2.0, "run.sample_interval": 1.0,
                          "initial.velocity.temperature": 0.0})
    with pytest.raises(EngineError, match=r"after 0 pair collisions .* count \d+ cannot be"):
        run_scene(scene, "edmd", RunOptions(out=tmp_path / "c.h5", progress=False))
    assert not (tmp_path / "c.h5").exists()


def test_cli_runs_the_edmd_engine(tmp_path, capsys):
    from demstudy.cli import main

    path = tmp_path / "scene.toml"
    path.write_text(ENGINE_SCENE)
    out = tmp_path / "cli.h5"
    assert main(["run", str(path), "--engine", "edmd", "--out", str(out), "--quiet",
                 "--set", "run.production=1.0"]) == 0
    assert read_results(out).attrs["engine"] == "edmd"
    assert main(["run", str(path), "--engine", "edmd", "--out", str(out), "--quiet",
                 "--set", "contact.law.model=campbell-exp"]) == 2
    assert "unsupported by edmd: contact.law.model" in capsys.readouterr().err


@pytest.mark.parametrize("size", [(20.0, 10.0, 8.0), (40.0, 10.0, 8.0), (200.0, 4.0, 4.0)])
def test_a_few_particles_run_in_an_elongated_periodic_box(tmp_path, size):
    """The cell budget (≤ 8 cells per particle, at least 64) coarsens the longest axis first:
    one sphere in an elongated box keeps 3 cells along its short axes instead of being
    refused (issue 13: a wider uniform cell made them fall below 3). Two elastic smooth
    spheres (zero total momentum) cross the cells and the periodic images: their energy stays
    exactly as given."""
    from demstudy.scene import load_scene

    scene = load_scene("cooling/hcs-3d", box={"size": list(size)},
                       particles={"count": 2, "solid_fraction": None},
                       contact={"restitution": 1.0, "tangential": {"model": "beta",
                                                                   "beta": -1.0}},
                       run={"equilibration": 0.0, "production": 20.0, "sample_interval": 1.0})
    res = read_results(run_scene(scene, "edmd", RunOptions(out=tmp_path / "two.h5",
                                                           progress=False)))
    ke = res.timeseries["kinetic_energy"]
    assert ke[0] > 0 and np.allclose(ke, ke[0], rtol=1e-12)
    assert res.attrs["events"] > 10  # cell crossings at least


def test_a_periodic_box_shorter_than_three_diameters_is_refused_by_name(tmp_path):
    from demstudy.scene import load_scene

    scene = load_scene("cooling/hcs-3d", box={"size": [20.0, 10.0, 2.5]},
                       particles={"count": 2, "solid_fraction": None},
                       run={"equilibration": 0.0, "production": 1.0, "sample_interval": 1.0})
    with pytest.raises(UnsupportedByEngine, match=r"box.size = .*at least 3 largest diameters"):
        run_scene(scene, "edmd", RunOptions(out=tmp_path / "x.h5", progress=False))


def test_resume_without_tc_keeps_the_checkpoints_tc_and_says_so(tmp_path, capfd):
    """A run stopped at a t_c that is not its dimension's default (here 1e-4 for discs; in
    practice a 3D run started at 1e-5 before spheres defaulted to 1e-6) continues at its own
    t_c when resumed without one, records it, and says at the end that it is not a default
    run; with another explicit t_c it is refused."""
    from demstudy.errors import EngineError

    scene = engine_scene({"run.production": 1.0})
    out = tmp_path / "r.h5"
    with pytest.raises(EngineError, match="--resume"):
        run_scene(scene, "edmd", RunOptions(out=out, progress=False, wall_limit=0.0,
                                            extra={"tc": 1e-4}))
    with pytest.raises(EngineError, match="checkpoint was run with --tc 0.0001"):
        run_scene(scene, "edmd", RunOptions(out=out, progress=False, resume=True,
                                            extra={"tc": 1e-5}))
    capfd.readouterr()
    res = read_results(run_scene(scene, "edmd", RunOptions(out=out, progress=False,
                                                           resume=True)))
    assert res.attrs["tc"] == 1e-4
    err = capfd.readouterr().err
    assert "resumed at the checkpoint's t_c = 0.0001, not the default 1e-05" in err
