"""The module under test comes from the build tree (PYTHONPATH, set by ctest); the command's
path and the examples' directory come from the environment too."""

import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]

# The remesh cache off (as ctest sets it): the suite writes nothing to ~/.cache and every
# remeshing scene remeshes (the GIL test times a load that remeshes). Tests of the cache name
# their own directory.
os.environ["FLEXFIT_CACHE_DIR"] = ""


@pytest.fixture
def examples():
    return ROOT / "examples"


def built_program(variable, how):
    """The path ctest gives in `variable` (a program of the build), or the test is skipped."""
    exe = os.environ.get(variable)
    if not exe:
        pytest.skip(f"{variable} not set (run through ctest{how})")
    return exe


@pytest.fixture
def flexfit_exe():
    return built_program("FLEXFIT_EXE", "")


@pytest.fixture
def haptic_loop_exe():
    return built_program("FLEXFIT_HAPTIC_LOOP", ", with FLEXFIT_BUILD_EXAMPLES")


def pytest_configure(config):
    # Dask's local cluster starts tornado's loop the way tornado 6.2 deprecates (Debian 12's
    # python3-distributed 2022.12): not ours to fix.
    config.addinivalue_line("filterwarnings", "ignore:make_current is deprecated:DeprecationWarning")
