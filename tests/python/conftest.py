"""Fixtures of the Python API's tests: the program beside the module, and small discs."""
import json
import os
import subprocess

import pytest

import spinesim

PROGRAM = os.environ.get("SPINESIM_PROGRAM", "")


@pytest.fixture(scope="session")
def program():
    """The `spinesim` program of the same build (the module's independent twin: same drivers,
    a separate process and the command line's own parsing)."""
    if not PROGRAM or not os.path.exists(PROGRAM):
        pytest.skip("SPINESIM_PROGRAM is not set to the built program")

    def run(*args, cwd=None, quiet=True):
        flags = ["--json", "--quiet"] if quiet else ["--json"]
        out = subprocess.run([PROGRAM, *map(str, args), *flags], cwd=cwd, capture_output=True,
                             text=True)
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)

    return run


@pytest.fixture(scope="session")
def disc_file(tmp_path_factory):
    """The structured haptic L4-L5 disc (12 sectors, 3 rings, 2 layers), written once."""
    path = tmp_path_factory.mktemp("disc") / "disc.vtu"
    spinesim.mesh_disc("L4-L5", structured=True, out=str(path))
    return path


@pytest.fixture()
def disc(disc_file):
    return spinesim.read_mesh(str(disc_file))


def assert_json_close(a, b, rtol=1e-9, atol=1e-9, where="$"):
    """Two JSON values equal: the same keys and strings, numbers to rtol/atol."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), f"{where}: keys {set(a) ^ set(b)}"
        for k in a:
            assert_json_close(a[k], b[k], rtol, atol, f"{where}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{where}: lengths"
        for i, (x, y) in enumerate(zip(a, b)):
            assert_json_close(x, y, rtol, atol, f"{where}[{i}]")
    elif isinstance(a, (int, float)) and not isinstance(a, bool):
        assert abs(a - b) <= atol + rtol * abs(b), f"{where}: {a} != {b}"
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"
