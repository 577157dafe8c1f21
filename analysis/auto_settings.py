"""The automatic soft-contact settings (event-driven pilot, docs/contact.md) against the
accuracy ladders of docs/accuracy-cost.md: for each study scene, a LAMMPS run whose stiffness
the pilot chooses (the scene's soft.hardness removed), at ``--steps`` steps per contact;
its wall time, k*, and its error against the ladder's event-driven reference (the same
error rule as ``demstudy cost``).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the wall
speed or the shear rate sets the time scale). Run analysis/accuracy_cost.py first.

    python analysis/auto_settings.py [STUDY ...] [--steps 10]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import demstudy as ds
from demstudy.accuracy.analyze import run_error
from demstudy.accuracy.plan import stiffness_scale
from demstudy.engines.edmd import default_tc

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "analysis"))  # the studies' definitions
from accuracy_cost import STUDIES, steady_state  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("studies", nargs="*", default=["le3d-0.3", "couette", "poiseuille"])
    parser.add_argument("--steps", type=float, default=10.0)
    parser.add_argument("--out", type=Path, default=ROOT / "results" / "accuracy-cost")
    args = parser.parse_args(argv)
    print("| flow | k* (pilot) | basis | wall (s) | error | noise floor |")
    print("|---|---|---|---|---|---|")
    for name in args.studies:
        spec = STUDIES[name]
        folder = args.out / name
        overrides = list(spec.get("overrides", []))
        if spec.get("steady"):
            overrides += steady_state(spec["scene"], folder)
        scene = ds.load_scene(spec["scene"], overrides)
        soft = scene.soft.model_copy(update={"hardness": None, "stiffness": None,
                                             "steps_per_contact": args.steps})
        scene = scene.model_copy(update={"soft": soft})
        res = ds.run(scene, engine="lammps", out=args.out / "auto" / f"{name}.h5",
                     progress=False)
        # the cost study's references at the event-driven default for the scene's dimension
        tc = default_tc(scene.dimension)
        refs = sorted(str(p) for p in folder.glob(f"ref-edmd-tc{tc:g}-r*.h5"))
        if not refs:
            raise SystemExit(f"{folder}: no reference ref-edmd-tc{tc:g}-r*.h5 (run the cost "
                             "study there first)")
        (comparison,) = ds.compare(refs, res)
        err = run_error(comparison)
        kstar = float(res.attrs["kn"]) / stiffness_scale(scene).unit
        print(f"| {name} | {kstar:.3g} | {res.attrs.get('stiffness_basis')} | "
              f"{res.attrs['wall_seconds']:.3g} | {err.error:.3f} ({err.field}) | "
              f"{err.floor:.3f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
