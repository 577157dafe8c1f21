"""`demstudy plot`: one figure per kind from results files written by the real writers and
analyses (synthetic frames through `demstudy analyze`, and a short event-driven homogeneous
cooling run); the plotted Line2D data must equal the stored datasets or the theory functions.
Dimensionless particle units: d = 1, m = 1, g = 1 with gravity."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from demstudy.analysis.derived import campbell_depth
from demstudy.cli import main
from demstudy.io.results import Results, read_results, write_results
from demstudy.plot import plot_profiles
from demstudy.plots import KINDS, draw, output_path, parse_kinds
from demstudy.plots.common import Run
from demstudy.plots.waves import dominant_plane, spectrum_image
from demstudy.scene import load_scene, scene_to_toml

INPUTS = Path(__file__).resolve().parent.parent / "inputs"
CHUTE = INPUTS / "campbell1982" / "chute-30.toml"
COUETTE = INPUTS / "campbell1982" / "couette-noslip.toml"
CHANNEL_3D = INPUTS / "malik2008" / "waves-phi0.15-L45W15H15.toml"
ATTRS = {"engine": "synthetic", "engine_version": "test 1", "equilibration_end": 0.0}


def _frames(scene, n, frames, y_range, rng, shear=0.0):
    dim, size = scene.dimension, np.asarray(scene.box.size, float)
    lo, hi = np.full(dim, 0.5), size - 0.5
    lo[1], hi[1] = y_range
    pos = rng.uniform(lo, hi, (frames, n, dim))
    vel = rng.normal(scale=0.5, size=(frames, n, dim))
    vel[..., 0] += shear * pos[..., 1]
    return {"time": np.arange(frames, dtype=float), "position": pos, "velocity": vel,
            "angular_velocity": rng.normal(size=(frames, n, 1 if dim == 2 else 3)),
            "radius": np.full((frames, n), 0.5), "box_lo": np.zeros((frames, dim)),
            "box_hi": np.tile(size, (frames, 1)), "tilt": np.zeros(frames)}


def _collision_log(rng, m, height, t_end):
    n = rng.normal(size=(m, 2))
    n /= np.linalg.norm(n, axis=1)[:, None]
    pos = np.stack([rng.uniform(0, 4.8, m), rng.uniform(0.5, height, m)], axis=1)
    return {"time": np.sort(rng.uniform(0, t_end, m)), "kind": np.zeros(m, np.int8),
            "position": pos, "normal": n, "branch": n, "impulse": -n,
            "velocity": rng.normal(size=(m, 2)), "spin_velocity": rng.normal(size=(m, 2))}


@pytest.fixture(scope="module")
def chute(tmp_path_factory):
    """A 2D chute (gravity, open top) with profiles, stress (kinetic + collisional, lower wall,
    momentum balance), vdf, gr, vcorr, waves and angles; no lambda (3D only)."""
    path = tmp_path_factory.mktemp("chute") / "chute.h5"
    scene = load_scene(CHUTE)
    rng = np.random.default_rng(3)
    n_frames, n_bins = 12, 40
    frames = _frames(scene, 40, n_frames, (0.5, 12.0), rng, shear=0.3)
    force = np.tile([-3.0, -20.0], (n_frames, 1)) + rng.normal(scale=0.5, size=(n_frames, 2))
    coll = rng.normal(scale=0.1, size=(n_bins, 2, 2))
    write_results(path, Results(
        attrs={**ATTRS, "scene_toml": scene_to_toml(scene), "scene_name": scene.meta.name},
        timeseries={"time": frames["time"], "wall_force_lower": force},
        frames=frames,
        groups={"collisions": _collision_log(rng, 3000, 12.0, n_frames - 1.0),
                "stress": {"collisional": coll, "collisional_err": np.abs(coll) * 0.1}}))
    assert main(["analyze", str(path), "--what", "profiles,vdf,gr,vcorr,waves"]) == 0
    assert main(["analyze", str(path), "--what", "angles,stress"]) == 0
    return path


@pytest.fixture(scope="module")
def couette(tmp_path_factory):
    """A 2D Couette cell (walls at y = 0, 12, width 4.8) holding an uncorrelated gas: 40
    points uniform in x over the period and in y ∈ [0.5, 11.5], 400 frames, u_x = y/12 plus
    noise; `demstudy analyze --what profiles,structure,cgprofiles`. Its structure
    distributions tend to the test region's number density 40/(4.8 × 11)."""
    path = tmp_path_factory.mktemp("couette") / "couette.h5"
    scene = load_scene(COUETTE)
    rng = np.random.default_rng(11)
    n, n_frames = 40, 400
    pos = np.stack([rng.uniform(0.0, 4.8, (n_frames, n)),
                    rng.uniform(0.5, 11.5, (n_frames, n))], axis=2)
    vel = rng.normal(scale=0.05, size=(n_frames, n, 2))
    vel[..., 0] += pos[..., 1] / 12.0
    frames = {"time": np.arange(n_frames, dtype=float), "position": pos, "velocity": vel,
              "angular_velocity": rng.normal(size=(n_frames, n, 1)),
              "radius": np.full((n_frames, n), 0.5), "box_lo": np.zeros((n_frames, 2)),
              "box_hi": np.tile([4.8, 12.0], (n_frames, 1)), "tilt": np.zeros(n_frames)}
    write_results(path, Results(
        attrs={**ATTRS, "scene_toml": scene_to_toml(scene), "scene_name": scene.meta.name},
        timeseries={"time": frames["time"]}, frames=frames))
    assert main(["analyze", str(path), "--what", "profiles,structure,cgprofiles"]) == 0
    return path


@pytest.fixture(scope="module")
def cooling(tmp_path_factory):
    """A real homogeneous cooling run: 1000 smooth spheres, φ = 0.1, e = 0.8, T0 = 1 in a
    periodic cube, `demstudy run --engine edmd` up to t = 30 ≈ 3 t0 (about 2 s)."""
    from edmd_helpers import make_scene

    folder = tmp_path_factory.mktemp("cooling")
    scene = make_scene(3, 0.1, 1000, seed=4, e=0.8, production=30.0, sample=1.0,
                       extra='[meta]\nname = "hcs-test"')
    (folder / "hcs.toml").write_text(scene_to_toml(scene))
    path = folder / "hcs.h5"
    assert main(["run", str(folder / "hcs.toml"), "--engine", "edmd", "--out", str(path),
                 "--quiet"]) == 0
    return path


@pytest.fixture(scope="module")
def channel(tmp_path_factory):
    """A 3D channel (walls at y = 0, 15) with lambda and waves only."""
    path = tmp_path_factory.mktemp("channel") / "channel.h5"
    scene = load_scene(CHANNEL_3D)
    frames = _frames(scene, 300, 4, (0.5, 14.5), np.random.default_rng(5))
    write_results(path, Results(attrs={**ATTRS, "scene_toml": scene_to_toml(scene),
                                       "scene_name": scene.meta.name}, frames=frames))
    assert main(["analyze", str(path), "--what", "lambda,waves"]) == 0
    return path


@pytest.fixture(scope="module")
def freepath(tmp_path_factory):
    """A results file with only ``/statistics/freepath``, from the real analysis
    (FreePath fed with flight_chunks, Enskog references from a profile overlay) on synthetic
    exponential flights (mean time 2, speed 1.5) of 3000 particles started in y ∈ [0, 4],
    written by write_results."""
    from demstudy.analysis.collisions import FreePath, flight_chunks

    rng = np.random.default_rng(7)
    ends = rng.random((3000, 1)) + np.cumsum(rng.exponential(2.0, (3000, 30)), axis=1)
    starts, taus = ends[:, :-1], np.diff(ends, axis=1)
    done = ends[:, 1:] <= 50.0
    starts, taus = starts[done], taus[done]
    y = rng.uniform(0.0, 4.0, taus.size)
    flights = {"t0": 0.0, "t1": 50.0, "start_time": starts, "tau": taus, "length": 1.5 * taus,
               "start": np.column_stack([np.zeros_like(y), y]), "event_time": starts,
               "event_y": y}
    edges = np.linspace(0.0, 4.0, 5)
    ana = FreePath(edges, 24.0, 16.0, width=4.0).run(flight_chunks(flights, 16)).finish()
    ana.overlay({"y": 0.5 * (edges[1:] + edges[:-1]), "solid_fraction": np.full(4, 0.1),
                 "temperature": np.full(4, 1.0), "velocity": np.zeros((4, 3))},
                cross_section=100.0)
    ana.attrs["knudsen_width_is"] = "wall gap"
    path = tmp_path_factory.mktemp("freepath") / "fp.h5"
    return write_results(path, Results(attrs=dict(ATTRS), groups={
        "statistics/freepath": ana.results}, group_attrs={"statistics/freepath": ana.attrs}))


def line(fig, gid):
    """The data line (the first Line2D) carrying ``gid``."""
    found = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == gid]
    assert found, f"no line {gid!r}"
    return found[0]


def same(ln, x, y):
    np.testing.assert_array_equal(np.asarray(ln.get_xdata(), float), np.asarray(x, float))
    np.testing.assert_array_equal(np.asarray(ln.get_ydata(), float), np.asarray(y, float))


def footer(fig):
    return " ".join(t.get_text() for t in fig.texts)


def test_all_kinds_write_pngs_and_skip_the_absent_one(chute, tmp_path, capsys):
    out = tmp_path / "fig.png"
    assert main(["plot", str(chute), "--kind", "all", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    absent = ("structure", "freepath", "lambda", "cgprofiles", "cooling", "health")  # KINDS order
    drawn = [k for k in KINDS if k not in absent]
    for kind in drawn:
        png = tmp_path / f"fig-{kind}.png"
        assert f"figure: {png}" in cap.out
        assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 20_000, kind
    assert not (tmp_path / "fig-lambda.png").exists()
    assert not (tmp_path / "fig-cooling.png").exists()  # a chute is not a cooling run
    assert not (tmp_path / "fig-freepath.png").exists()  # its log has no particle indices
    assert not (tmp_path / "fig-structure.png").exists()
    assert not (tmp_path / "fig-cgprofiles.png").exists()
    notices = [ln for ln in cap.err.splitlines() if ln]
    assert [ln.split(": ")[3].split(" skipped")[0] for ln in notices] == list(absent)
    assert "no /statistics/structure" in notices[0] and "--what structure" in notices[0]
    assert "--what freepath" in notices[1]
    assert "lambda skipped" in notices[2] and "--what lambda" in notices[2]
    assert "no /statistics/cgprofiles" in notices[3] and "--what cgprofiles" in notices[3]
    assert "cooling skipped" in notices[4] and "homogeneous cooling" in notices[4]
    assert "no /health" in notices[5] and "event-driven runs are hard" in notices[5]
    assert "Traceback" not in cap.err


def test_profiles_and_stress_plot_the_stored_data(chute, tmp_path):
    run = Run.load(chute)
    prof = read_results(chute).profiles
    name = chute.name
    fig = draw("profiles", [run])
    occupied = prof["solid_fraction"] > 1e-3
    same(line(fig, f"{name}:solid_fraction"), prof["solid_fraction"], prof["y"])
    same(line(fig, f"{name}:velocity"), prof["velocity"][occupied, 0], prof["y"][occupied])
    same(line(fig, f"{name}:temperature"), prof["temperature"][occupied], prof["y"][occupied])
    assert "d = 1, m = 1, g = 1" in footer(fig) and "synthetic (test 1)" in footer(fig)
    assert "gravity acts" in footer(fig)

    scaled = draw("profiles", [run], scaled=True)  # open top: Campbell's flow depth
    depth = campbell_depth(prof, 0.0)
    same(line(scaled, f"{name}:solid_fraction"), prof["solid_fraction"], prof["y"] / depth)
    assert "flow depth" in scaled.axes[0].get_ylabel()

    st = read_results(chute).groups["statistics/stress"]
    fig = draw("stress", [run])
    for key in ("kinetic", "collisional", "total"):
        same(line(fig, f"{name}:{key}:xy"), st[key][:, 0, 1], st["y"])
        same(line(fig, f"{name}:{key}:yy"), st[key][:, 1, 1], st["y"])
    same(line(fig, f"{name}:wall_lower:yy"), [st["wall_lower"][1]], [st["edges"][0]])
    same(line(fig, f"{name}:wall_lower:xy"), [st["wall_lower"][0]], [st["edges"][0]])
    same(line(fig, f"{name}:balance:xy"), -st["balance_tau_xy"], st["y"])
    same(line(fig, f"{name}:balance:yy"), st["balance_tau_yy"], st["y"])


def test_distributions_and_correlations_plot_the_stored_data(chute):
    run = Run.load(chute)
    groups = read_results(chute).groups
    name = chute.name

    vdf = groups["statistics/vdf"]
    fig = draw("vdf", [run], bins=[2, 5])
    for b in (1, 4):
        for k, x in enumerate(("X1", "X2", "X3", "X4", "X5")):
            same(line(fig, f"{name}:X:{b}:{x}"), vdf["X_centres"], vdf["X"][b, k])
        for c, comp in enumerate(("u", "v", "omega_z")):
            same(line(fig, f"{name}:malik_P:{b}:{comp}"), vdf["malik_centres"],
                 vdf["malik_P"][b, c])
    same(line(fig, f"{name}:X_reference:-:X4"), vdf["X_centres"], vdf["X_reference"][3])
    same(line(fig, f"{name}:gaussian:-:v"), vdf["malik_centres"], vdf["gaussian"])

    ang = groups["statistics/angles"]
    fig = draw("angles", [run], bins=[3])
    deg = np.degrees(ang["theta"])
    for conv in ("text", "listing"):
        same(line(fig, f"{name}:p_{conv}:2"), deg, ang[f"p_{conv}"][2])
        same(line(fig, f"{name}:sj_{conv}_R:2"), deg, ang[f"sj_{conv}_R"][2])
    assert np.all(np.isfinite(ang["sj_text_R"][2]))

    gr = groups["statistics/gr"]
    fig = draw("gr", [run])
    same(line(fig, f"{name}:gr:0"), gr["r"], gr["g"][0])

    vc = groups["statistics/vcorr"]
    fig = draw("vcorr", [run])  # default bins: first occupied, fourth, middle
    first = int(np.flatnonzero(vc["count"] > 0)[0])
    for a in (0, 1):
        same(line(fig, f"{name}:C:{first}:{a}"), vc["r"], vc["C"][first, a])
        same(line(fig, f"{name}:C:{first + 3}:{a}"), vc["r"], vc["C"][first + 3, a])
    assert vc["C_offdiag"].shape == (vc["C"].shape[0], 1, vc["r"].size)  # 2D: xy only
    for b in (first, first + 3):
        same(line(fig, f"{name}:C_offdiag:{b}:0"), vc["r"], vc["C_offdiag"][b, 0])
    titles = [ax.get_title() for ax in fig.axes if ax.get_visible()]
    assert titles == ["C_xx(r)", "C_yy(r)", "C_xy(r)"]


def test_waves_plot_spectrum_field_and_series(chute, channel):
    for path in (chute, channel):
        run = Run.load(path)
        data, attrs = run.group("waves")
        plane = dominant_plane(data, attrs)
        fig = draw("waves", [run])
        mesh = [c for ax in fig.axes for c in ax.collections
                if c.get_gid() == f"{path.name}:spectrum_{plane}"]
        _ka, _kb, power = spectrum_image(data, plane)
        np.testing.assert_array_equal(np.ma.getdata(mesh[0].get_array()).ravel(),
                                      np.ma.getdata(power).ravel())
        assert mesh[0].norm.__class__.__name__ == "LogNorm"
        assert np.ma.getmaskarray(power)[list(_kb).index(0), list(_ka).index(0)]  # (0,0) masked
        for j in range(data[f"series_modes_{plane}"].shape[0]):
            same(line(fig, f"{path.name}:series_{plane}:{j}"), data["series_time"],
                 data[f"series_{plane}"][:, j])
    # 3D: no dominant family in a random gas, the xy plane is drawn
    data, attrs = Run.load(channel).group("waves")
    assert dominant_plane(data, attrs) == "xy"
    fake = dict(data, dominant_yz=np.array([[1, 1]]))
    assert dominant_plane(fake, attrs) == "yz"


def test_lambda_and_absent_kinds_give_notices_and_exit_0(channel, tmp_path, capsys):
    run = Run.load(channel)
    lam = read_results(channel).groups["statistics/lambda"]
    fig = draw("lambda", [run])
    mask = lam["count"] > 0
    same(line(fig, f"{channel.name}:lambda"), lam["lambda"][mask], lam["y"][mask])
    assert "gravity acts here" in footer(fig)

    out = tmp_path / "f.png"
    assert main(["plot", str(channel), "--kind", "profiles,lambda", "--kind", "vdf",
                 "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert cap.out.strip() == f"figure: {tmp_path / 'f-lambda.png'}"
    assert (tmp_path / "f-lambda.png").stat().st_size > 10_000
    notices = cap.err.strip().splitlines()
    assert len(notices) == 2 and "profiles skipped" in notices[0] and "vdf skipped" in notices[1]

    assert main(["plot", str(channel), "--kind", "stress", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert not out.exists() and "stress skipped" in cap.err and "no figure" in cap.err
    assert "Traceback" not in cap.err


def test_unknown_kind_is_refused_with_exit_2(chute, capsys):
    assert main(["plot", str(chute), "--kind", "profiles,spectra"]) == 2
    err = capsys.readouterr().err
    assert "'spectra'" in err and all(k in err for k in KINDS) and "Traceback" not in err
    with pytest.raises(ValueError, match="allowed"):
        parse_kinds(["gr,nope"])


def test_scaled_profiles_between_walls_and_overlay(chute, tmp_path):
    """Couette cell: H = the wall gap; two files overlay in one figure; plot_profiles keeps
    its signature (returns the path)."""
    scene = load_scene(COUETTE)
    edges = np.linspace(0.0, 12.0, 13)
    y = 0.5 * (edges[1:] + edges[:-1])
    prof = {"y": y, "edges": edges, "solid_fraction": np.full(12, 0.5),
            "velocity": np.stack([y / 12, np.zeros(12)], axis=1),
            "temperature": np.full(12, 0.1), "rotational_temperature": np.full(12, 0.05)}
    path = write_results(tmp_path / "couette.h5", Results(
        attrs={**ATTRS, "scene_toml": scene_to_toml(scene), "scene_name": scene.meta.name},
        profiles=prof, profile_attrs={"axis": "y"}))
    fig = draw("profiles", [Run.load(path), Run.load(chute)], scaled=True)
    same(line(fig, "couette.h5:velocity"), y / 12, y / 12.0)
    assert "see the legend" in fig.axes[0].get_ylabel()  # gap and flow depth mixed
    labels = fig.axes[0].get_legend_handles_labels()[1]
    assert any("H = 12" in label for label in labels)
    fig = draw("profiles", [Run.load(path)], scaled=True)
    assert "gap between the walls" in fig.axes[0].get_ylabel()
    assert "no gravity here" in footer(fig)
    out = plot_profiles([path], tmp_path / "p.png")
    assert out == tmp_path / "p.png" and out.stat().st_size > 10_000
    assert main(["plot", str(path), "--scaled", "-o", str(tmp_path / "s.png")]) == 0
    assert (tmp_path / "s.png").stat().st_size > 10_000


def test_output_names():
    assert output_path("a/fig.png", "vdf", False) == Path("a/fig.png")
    assert output_path("a/fig.png", "vdf", True) == Path("a/fig-vdf.png")
    assert output_path("a/fig", "gr", True) == Path("a/fig-gr.png")
    assert output_path(None, "waves", True) == Path("waves.png")


def test_equation_of_state_plots_chi_against_nu(chute):
    """χ per bin from the stored total P_yy and the profiles (derived.equation_of_state), at
    each bin's ν; the theory curve is campbell_chi for the scene's e."""
    from demstudy.analysis.derived import equation_of_state
    from demstudy.theory import campbell_chi

    run = Run.load(chute)
    res = read_results(chute)
    st, prof = res.groups["statistics/stress"], res.profiles
    chi, _err = equation_of_state(prof, st["total"][:, 1, 1], st["total_err"][:, 1, 1])
    nu = prof["solid_fraction"]
    ok = np.isfinite(chi) & (nu > 0.02)
    assert ok.sum() >= 3
    fig = draw("eos", [run])
    same(line(fig, f"{chute.name}:chi"), nu[ok], chi[ok])
    theory = line(fig, f"{chute.name}:chi_theory")
    x = np.asarray(theory.get_xdata(), float)
    e = run.scene.contact.restitution
    np.testing.assert_allclose(theory.get_ydata(), campbell_chi(x, 2, e), rtol=1e-12)
    assert "Henderson" in fig._suptitle.get_text()


def test_vcorr_plot_draws_the_three_off_diagonal_components_in_3d(channel, tmp_path):
    """3D: C_xy, C_xz, C_yz below C_xx, C_yy, C_zz, each the stored C_offdiag row."""
    assert main(["analyze", str(channel), "--what", "vcorr", "--out",
                 str(tmp_path / "vc.h5")]) == 0
    path = tmp_path / "vc.h5"
    vc = read_results(path).groups["statistics/vcorr"]
    fig = draw("vcorr", [Run.load(path)], bins=[2])
    for p in range(3):
        same(line(fig, f"vc.h5:C_offdiag:1:{p}"), vc["r"], vc["C_offdiag"][1, p])
    titles = [ax.get_title() for ax in fig.axes]
    assert titles[3:] == ["C_xy(r)", "C_xz(r)", "C_yz(r)"]


def test_cooling_plot_overlays_haff_on_a_real_edmd_run(cooling, chute, tmp_path, capsys):
    """T/T0 from the kinetic energy (centre-of-mass motion removed, dim (N − 1) degrees of
    freedom) and Haff's T0/(1 + t/t0)² from demstudy.theory with the scene's ν and e, both
    on log–log axes; the run follows Haff within 10 % up to 3 t0 (a t0 off by 2 would miss
    by > 60 %). Other runs skip the kind with a notice."""
    from demstudy.theory import haff_t0, haff_temperature

    run = Run.load(cooling)
    ts, scene = read_results(cooling).timeseries, run.scene
    n = scene.n_particles
    temp = (2 * ts["kinetic_energy"] - (ts["momentum"] ** 2).sum(1) / n) / (3 * (n - 1))
    t = ts["time"] - ts["time"][0]
    fig = draw("cooling", [run])
    same(line(fig, "hcs.h5:temperature"), t[1:], temp[1:] / temp[0])
    haff = line(fig, "hcs.h5:haff")
    nu, e = scene.solid_fraction, scene.contact.restitution
    assert (nu, e) == (pytest.approx(0.1), 0.8)
    np.testing.assert_array_equal(haff.get_xdata(), t[1:])
    np.testing.assert_allclose(haff.get_ydata(),
                               haff_temperature(t[1:], nu, temp[0], 3, e) / temp[0], rtol=1e-12)
    t0 = haff_t0(nu, temp[0], 3, e)
    assert f"t0 = {t0:.3g}" in haff.get_label() and t[-1] > 3 * t0 * 0.95
    assert fig.axes[0].get_xscale() == fig.axes[0].get_yscale() == "log"
    ratio = temp[1:] / temp[0] / np.asarray(haff.get_ydata())
    assert temp[-1] / temp[0] < 0.1 and np.all(np.abs(ratio - 1) < 0.1)
    assert "initial temperature sets the time scale" in footer(fig)

    out = tmp_path / "c.png"  # `all` includes cooling for a cooling run (the chute skips it)
    assert main(["plot", str(cooling), "--kind", "all", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert f"figure: {tmp_path / 'c-cooling.png'}" in cap.out
    assert (tmp_path / "c-cooling.png").stat().st_size > 20_000
    assert "cooling skipped" not in cap.err and "Traceback" not in cap.err
    assert main(["plot", str(chute), "--kind", "cooling", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert not out.exists() and "cooling skipped" in cap.err and "no figure" in cap.err


def test_freepath_plots_the_stored_pdfs_and_the_exponentials(freepath, chute, tmp_path, capsys):
    """P(λ), P(τ) per chosen bin equal the stored rows; the dashed reference is
    exp(−x/⟨x⟩)/⟨x⟩ with the bin's stored mean; the legend states ⟨λ⟩, Kn and Enskog's λ;
    `all` draws the kind for a file that has it (and only it)."""
    from demstudy.theory import mean_free_path

    fp = read_results(freepath).groups["statistics/freepath"]
    assert np.all(fp["flights"] > 0)
    fig = draw("freepath", [Run.load(freepath)], bins=[1, 3])
    for b in (0, 2):
        for x, mean in (("lambda", "mean_free_path"), ("tau", "mean_free_time")):
            same(line(fig, f"fp.h5:p_{x}:{b}"), fp[x], fp[f"p_{x}"][b])
            ref = line(fig, f"fp.h5:exp_{x}:{b}")
            np.testing.assert_array_equal(ref.get_xdata(), fp[x])
            m = fp[mean][b]
            np.testing.assert_allclose(ref.get_ydata(), np.exp(-fp[x] / m) / m, rtol=1e-12)
            assert ref.get_linestyle() == "--"
        assert fp["mean_free_path"][b] == pytest.approx(3.0, rel=0.05)  # 1.5 x ⟨τ⟩ = 2
    assert all(ax.get_yscale() == "log" for ax in fig.axes)
    assert not any(ln.get_gid() == "fp.h5:p_lambda:1" for ax in fig.axes for ln in ax.lines)
    labels = " ".join(fig.axes[0].get_legend_handles_labels()[1])
    assert f"⟨λ⟩ = {fp['mean_free_path'][2]:.3g}" in labels
    assert f"Kn = {fp['knudsen'][2]:.3g}" in labels
    assert f"λ_E = {mean_free_path(0.1, 3):.3g}" in labels
    assert "W = 4 (wall gap)" in fig._suptitle.get_text()
    default = draw("freepath", [Run.load(freepath)])  # first, fourth and middle bin
    assert {ln.get_gid() for ln in default.axes[1].lines} >= {f"fp.h5:p_tau:{b}" for b in (0, 2, 3)}

    out = tmp_path / "f.png"
    assert main(["plot", str(freepath), str(chute), "--kind", "all", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert f"figure: {tmp_path / 'f-freepath.png'}" in cap.out
    assert (tmp_path / "f-freepath.png").stat().st_size > 20_000
    assert "fp.h5: no /profiles: profiles skipped" in cap.err
    assert "chute.h5: no /statistics/freepath: freepath skipped" in cap.err
    assert "Traceback" not in cap.err


def test_profiles_draw_malik_cell_temperatures_dashed(channel, tmp_path):
    """`analyze --what profiles --z-cells 3` adds cell_temperature and
    cell_rotational_temperature: dashed next to the strip temperatures, in the strip's
    colour, labelled with the number of z-cells; without z-cells nothing is added."""
    path = tmp_path / "zc.h5"
    assert main(["analyze", str(channel), "--what", "profiles", "--z-cells", "3",
                 "--out", str(path)]) == 0
    res = read_results(path)
    prof = res.profiles
    assert int(res.profile_attrs["z_cells"]) == 3
    ok = prof["solid_fraction"] > 1e-3
    fig = draw("profiles", [Run.load(path)])
    for key in ("temperature", "rotational_temperature"):
        strip, cell = line(fig, f"zc.h5:{key}"), line(fig, f"zc.h5:cell_{key}")
        same(strip, prof[key][ok], prof["y"][ok])
        same(cell, prof[f"cell_{key}"][ok], prof["y"][ok])
        assert cell.get_linestyle() == "--" and cell.get_color() == strip.get_color()
        ax = cell.axes
        assert "3 z-cells (Malik)" in [t.get_text() for t in ax.get_legend().get_texts()]
    assert not np.array_equal(prof["cell_temperature"], prof["temperature"])

    strip_only = tmp_path / "strip.h5"
    assert main(["analyze", str(channel), "--what", "profiles", "--out", str(strip_only)]) == 0
    fig = draw("profiles", [Run.load(strip_only)])
    assert not any("cell_" in str(ln.get_gid()) for ax in fig.axes for ln in ax.lines)


def _errorbars(fig, gid):
    """(x, y, half-length) of the vertical error bars of the errorbar drawn with ``gid``."""
    found = [c for ax in fig.axes for c in ax.containers
             if c.lines[0] is not None and c.lines[0].get_gid() == gid]
    assert found, f"no error bars {gid!r}"
    seg = np.asarray(found[0].lines[2][0].get_segments(), float)  # (n, 2 ends, xy)
    return seg[:, 0, 0], seg.mean(axis=1)[:, 1], 0.5 * (seg[:, 1, 1] - seg[:, 0, 1])


def test_structure_plots_the_stored_distributions_and_campbells_mean_density(couette):
    """Normal and parallel distributions (and their error bars) equal the stored rows; the
    dashed reference is the run's mean number density from /profiles (Σ n_b w_b / H, which
    for 40 discs between walls 12 apart in a 4.8 wide cell is 40/(4.8 × 12) exactly), the
    dotted one the test region's density; the uncorrelated gas lies on the dotted line (the
    bins near the walls hold fewer centres, so not on the dashed one)."""
    res = read_results(couette)
    st, prof = res.groups["statistics/structure"], res.profiles
    fig = draw("structure", [Run.load(couette)])
    name = couette.name
    for key in ("normal", "parallel"):
        same(line(fig, f"{name}:{key}"), st["r"], st[key])
        x, y, half = _errorbars(fig, f"{name}:{key}")
        np.testing.assert_allclose(x, st["r"])
        np.testing.assert_allclose(y, st[key], rtol=1e-12)
        np.testing.assert_allclose(half, st[f"{key}_err"], rtol=1e-9, atol=1e-15)
        assert np.all(st[f"{key}_err"] > 0)
    widths = np.diff(prof["edges"])
    n_mean = np.sum(np.nan_to_num(prof["number_density"]) * widths) / widths.sum()
    assert n_mean == pytest.approx(40 / (4.8 * 12.0), rel=1e-9)
    n_test = 40 / (4.8 * 11.0)  # the gas fills y ∈ [0.5, 11.5]: uniform in the middle
    for key in ("normal", "parallel"):
        mean_line = line(fig, f"{name}:n_mean:{key}")
        np.testing.assert_allclose(mean_line.get_ydata(), [n_mean, n_mean], rtol=1e-12)
        assert mean_line.get_linestyle() == "--"
        assert mean_line.get_color() == line(fig, f"{name}:{key}").get_color()
        test_line = line(fig, f"{name}:n_test:{key}")
        assert test_line.get_ydata()[0] == pytest.approx(n_test, rel=0.03)
        # an uncorrelated gas: Campbell's normalisation gives the local number density
        assert np.mean(st[key]) == pytest.approx(n_test, rel=0.04), key
        assert np.mean(st[key]) > 1.04 * n_mean
    labels = fig.axes[-1].get_legend().get_texts()
    assert any(f"n̄ = {n_mean:.3g}" in t.get_text() for t in labels)
    assert fig.axes[0].get_ylabel() == "number density of partners (d⁻²)"
    assert fig.axes[0].get_xlabel() == "|Δy| (d)" and fig.axes[1].get_xlabel() == "|Δx| (d)"
    assert "no gravity here" in footer(fig) and "synthetic (test 1)" in footer(fig)


def test_cgprofiles_overlay_the_binned_profiles_of_the_same_file(couette):
    """The coarse-grained ν, u_x, T (lines) and their bands equal the stored arrays, the
    binned /profiles of the same file are drawn as markers with error bars in the same
    colour; both agree in the bulk; ``scaled`` divides both by the wall gap."""
    res = read_results(couette)
    cg, prof = res.groups["statistics/cgprofiles"], res.profiles
    name = couette.name
    fig = draw("cgprofiles", [Run.load(couette)])
    seen = cg["solid_fraction"] > 1e-3
    occupied = prof["solid_fraction"] > 1e-3
    for key in ("solid_fraction", "velocity", "temperature"):
        val, err = cg[key], cg[f"{key}_err"]
        bval, berr = prof[key], prof[f"{key}_err"]
        if val.ndim == 2:
            val, err, bval, berr = val[:, 0], err[:, 0], bval[:, 0], berr[:, 0]
        mask = np.isfinite(val) & (seen if key != "solid_fraction" else True)
        cg_line = line(fig, f"{name}:cg:{key}")
        same(cg_line, val[mask], cg["y"][mask])
        band = [c for ax in fig.axes for c in ax.collections
                if c.get_gid() == f"{name}:cg:{key}_err"]
        xs = band[0].get_paths()[0].vertices[:, 0]
        assert np.all(np.isin(val[mask] - err[mask], xs))
        assert np.all(np.isin(val[mask] + err[mask], xs))
        bmask = occupied if key != "solid_fraction" else np.ones_like(occupied)
        binned = line(fig, f"{name}:{key}")
        same(binned, bval[bmask], prof["y"][bmask])
        assert binned.get_linestyle() == "None" and binned.get_color() == cg_line.get_color()
        _x, _y, half = _errorbars_x(fig, f"{name}:{key}")
        np.testing.assert_allclose(half, berr[bmask], rtol=1e-9, atol=1e-15)
        # the same field: CG at the strip centres agrees in the bulk (2 < y < 10) ...
        bulk = (prof["y"] > 2) & (prof["y"] < 10)
        at_centres = np.interp(prof["y"][bulk], cg["y"], val)
        if key != "temperature":
            scale = np.max(np.abs(bval[bulk]))
            assert np.max(np.abs(at_centres - bval[bulk])) < 0.1 * scale, key
            continue
        # ... T once the gradient u' = 1/12 is taken out: u'² ⟨s²⟩/dim with ⟨s²⟩ the kernel's
        # variance (CG, point particles) or the strip's h²/12 plus a disc's R²/4 (binned)
        # (0.00034 apart, 11 % of T = 0.0025)
        grad2 = (1 / 12) ** 2
        kernel = float(res.group_attrs["statistics/cgprofiles"]["truncated_variance"])
        cg_t = np.mean(at_centres) - grad2 * kernel / 2
        bin_t = np.mean(bval[bulk]) - grad2 * (1 / 12 + 0.25 / 4) / 2
        assert cg_t == pytest.approx(0.05**2, rel=0.03)
        assert bin_t == pytest.approx(0.05**2, rel=0.03)
        assert cg_t == pytest.approx(bin_t, rel=0.01)
    assert fig.axes[1].get_xlabel() == "mean velocity u_x (d/τ)"
    assert "m d²/τ²" in fig.axes[2].get_xlabel() and fig.axes[0].get_ylabel() == "y (d)"

    scaled = draw("cgprofiles", [Run.load(couette)], scaled=True)
    same(line(scaled, f"{name}:cg:solid_fraction"), cg["solid_fraction"], cg["y"] / 12.0)
    same(line(scaled, f"{name}:solid_fraction"), prof["solid_fraction"], prof["y"] / 12.0)
    assert "gap between the walls" in scaled.axes[0].get_ylabel()


def _errorbars_x(fig, gid):
    """(x, y, half-length) of the horizontal error bars of the errorbar drawn with ``gid``."""
    found = [c for ax in fig.axes for c in ax.containers
             if c.lines[0] is not None and c.lines[0].get_gid() == gid]
    assert found, f"no error bars {gid!r}"
    seg = np.asarray(found[0].lines[2][0].get_segments(), float)
    return seg.mean(axis=1)[:, 0], seg[:, 0, 1], 0.5 * (seg[:, 1, 0] - seg[:, 0, 0])


def test_all_draws_structure_and_cgprofiles_where_present_and_overlays(couette, chute, channel,
                                                                        tmp_path, capsys):
    """`--kind all` on a file holding them writes both figures (no notice for them); on one
    without them it skips both with a notice; overlays: one curve per file, a 2D and a 3D
    structure file together, a file without /profiles (no reference line, CG only)."""
    out = tmp_path / "all.png"
    assert main(["plot", str(couette), "--kind", "all", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    for kind in ("structure", "cgprofiles", "profiles"):
        png = tmp_path / f"all-{kind}.png"
        assert f"figure: {png}" in cap.out and png.stat().st_size > 20_000, kind
    assert "structure skipped" not in cap.err and "cgprofiles skipped" not in cap.err

    assert main(["plot", str(chute), str(couette), "--kind", "structure,cgprofiles",
                 "-o", str(tmp_path / "two.png")]) == 0
    cap = capsys.readouterr()
    assert (tmp_path / "two-structure.png").exists() and (tmp_path / "two-cgprofiles.png").exists()
    assert "chute.h5: no /statistics/structure: structure skipped" in cap.err
    assert "chute.h5: no /statistics/cgprofiles: cgprofiles skipped" in cap.err

    path3 = tmp_path / "channel3d.h5"  # 3D, no /profiles
    assert main(["analyze", str(channel), "--what", "structure,cgprofiles",
                 "--out", str(path3)]) == 0
    st3 = read_results(path3).groups["statistics/structure"]
    fig = draw("structure", [Run.load(couette), Run.load(path3)])
    same(line(fig, "channel3d.h5:parallel"), st3["r"], st3["parallel"])
    st2 = read_results(couette).groups["statistics/structure"]
    same(line(fig, "couette.h5:parallel"), st2["r"], st2["parallel"])
    colours = {line(fig, f"{f}:normal").get_color() for f in ("couette.h5", "channel3d.h5")}
    assert len(colours) == 2
    gids = {ln.get_gid() for ax in fig.axes for ln in ax.lines}
    assert "couette.h5:n_mean:normal" in gids and not any(
        g and g.startswith("channel3d.h5:n_") for g in gids)
    assert "3D" in fig.axes[1].get_xlabel() and "d⁻³ in 3D" in fig.axes[0].get_ylabel()
    fig = draw("cgprofiles", [Run.load(path3)])
    cg3 = read_results(path3).groups["statistics/cgprofiles"]
    same(line(fig, "channel3d.h5:cg:solid_fraction"), cg3["solid_fraction"], cg3["y"])
    assert not any(ln.get_gid() == "channel3d.h5:solid_fraction" for ax in fig.axes
                   for ln in ax.lines)
    assert "Traceback" not in cap.err
