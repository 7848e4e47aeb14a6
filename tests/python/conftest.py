"""What the tests of the Python module share: the beamsim program they check
the module against (BSIM_EXE), the source tree's configs (BSIM_SOURCE_DIR),
both set by ctest (tests/CMakeLists.txt), and a runner of the program."""

import json
import os
import subprocess

import pytest

EXE = os.environ.get("BSIM_EXE", "build/beamsim")
SRC = os.environ.get("BSIM_SOURCE_DIR", ".")


def config(*parts):
    return os.path.join(SRC, "configs", *parts)


def cli(*args, check=True):
    """Runs beamsim ARGS; the completed process (text)."""
    p = subprocess.run([EXE, *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"beamsim {' '.join(map(str, args))}: exit {p.returncode}\n"
                             f"{p.stderr}")
    return p


def cli_json(*args):
    """beamsim run ... --json, parsed."""
    return json.loads(cli(*args, "--json").stdout)


def cli_message(*args):
    """The one-line message of a refused command: its first stderr line
    without "beamsim: ", and its exit status."""
    p = cli(*args, check=False)
    line = p.stderr.splitlines()[0]
    assert line.startswith("beamsim: "), p.stderr
    return line[len("beamsim: "):], p.returncode


@pytest.fixture
def h1():
    return config("thesis", "h1_symmetric.yaml")


@pytest.fixture
def gate():
    return config("thesis", "gate.yaml")
