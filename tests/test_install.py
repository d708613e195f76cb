"""An installed fixplan writes nothing into its own package folder (``pip uninstall`` would leave
such files behind, and the leftover folder would shadow a later editable install)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import fixplan

PACKAGE = Path(fixplan.__file__).resolve().parent


@pytest.mark.skipif(sys.platform in ("win32", "darwin"), reason="XDG_CACHE_HOME is Linux's")
def test_compiled_kernels_are_cached_in_the_user_cache_folder_not_in_the_package(tmp_path):
    environment = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    environment["XDG_CACHE_HOME"] = str(tmp_path)
    script = (
        "from fixplan import LimitSurface, pressure\n"
        "surface = LimitSurface(pressure.points([[0, 0], [0.01, 0]]), mu=0.5, normal_force=1.0)\n"
        "print(surface.safety_factor([0.1, 0.1, 0.0]))\n"
    )
    before = {p for p in PACKAGE.rglob("*") if p.suffix in (".nbi", ".nbc")}
    result = subprocess.run(
        [sys.executable, "-c", script], env=environment, capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr
    assert list((tmp_path / "fixplan" / "numba").rglob("*.nbi"))
    assert {p for p in PACKAGE.rglob("*") if p.suffix in (".nbi", ".nbc")} == before
