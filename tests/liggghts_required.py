"""LIGGGHTS's tests need the library (dimensionless particle units: d = 1, m = 1, g = 1 when
gravity acts)."""

import os


def require_liggghts(executable: bool = False) -> None:
    """LIGGGHTS is part of the set-up (`make install` installs it as root): its tests fail
    when it is missing, naming the fix, rather than skip a core path silently. Only an
    explicit DEMSTUDY_SKIP_LIGGGHTS=1 (a machine where it cannot be installed) skips them."""
    import shutil

    import pytest

    from demstudy.engines.liggghts.library import INSTALL_HINT, library_path

    missing = library_path() is None or (executable and shutil.which("liggghts") is None)
    if not missing:
        return
    if os.environ.get("DEMSTUDY_SKIP_LIGGGHTS") == "1":
        pytest.skip("LIGGGHTS is not installed (DEMSTUDY_SKIP_LIGGGHTS=1)")
    pytest.fail(f"LIGGGHTS is not installed: {INSTALL_HINT} (or set DEMSTUDY_SKIP_LIGGGHTS=1 "
                "to skip its tests)")
