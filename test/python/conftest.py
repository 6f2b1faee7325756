"""Shared fixtures of the Python module's tests (pytest, run by scripts/test.sh from the sourced
catkin workspace, where `import mvog` finds the built module).

The references written by C++ come from mvog_ray_export (src/tools/ray_export.cpp), found through
$MVOG_RAY_EXPORT or in lib/mvog of the sourced workspace ($CMAKE_PREFIX_PATH). The recordings are
read from $MVOG_DATA_DIR, else <repo>/../shared/data: without them the tests that need them skip,
except under CI=true, where they fail.
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
# A small recording: one synthetic spherical scan of 10,201 points (the data's README).
REFERENCE_RECORDING = "spherical_scan.graph"
REFERENCE_RESOLUTION = 0.1


def require(condition, message):
    """Skips the calling test unless `condition` holds; fails it instead under CI=true."""
    if condition:
        return
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail("CI=true and " + message)
    pytest.skip(message)


def data_directory():
    return Path(os.environ.get("MVOG_DATA_DIR") or REPO.parent / "shared" / "data")


def ray_export_tool():
    """The path of mvog_ray_export, or None."""
    explicit = os.environ.get("MVOG_RAY_EXPORT")
    if explicit:
        return Path(explicit)
    for prefix in filter(None, os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep)):
        candidate = Path(prefix) / "lib" / "mvog" / "mvog_ray_export"
        if candidate.is_file():
            return candidate
    return None


@pytest.fixture(scope="session")
def recording():
    """The path of the reference recording (skips without it, fails under CI=true)."""
    path = data_directory() / REFERENCE_RECORDING
    require(path.is_file(), "%s is missing: set MVOG_DATA_DIR to the shared data directory" % path)
    return path


@pytest.fixture(scope="session")
def reference(recording, tmp_path_factory):
    """The directory mvog_ray_export wrote for the reference recording, and its JSON line."""
    tool = ray_export_tool()
    require(tool is not None and tool.is_file(),
            "mvog_ray_export not found: source the built workspace or set MVOG_RAY_EXPORT")
    out = tmp_path_factory.mktemp("reference")
    printed = subprocess.run(
        [str(tool), str(recording), str(out), "--resolution", str(REFERENCE_RESOLUTION)],
        check=True, capture_output=True, text=True).stdout
    return out, json.loads(printed)
