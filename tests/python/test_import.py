"""Importing the package from a Python that cannot load it says what it
needs and which Python to run (beamsim/__init__.py): NumPy missing (Python
started with -S, which leaves out the site directories where Debian's and
pip's NumPy live), and the Python the extension was built for named, the
one running these tests."""

import os
import subprocess
import sys

import beamsim
from beamsim import _built


def test_the_python_it_was_built_for_runs_the_tests():
    assert os.path.realpath(_built.python) == os.path.realpath(sys.executable)
    assert _built.version == "%d.%d" % sys.version_info[:2]


def test_a_python_without_numpy_is_told_what_to_run():
    package = os.path.dirname(os.path.dirname(beamsim.__file__))
    code = f"import sys; sys.path.insert(0, {package!r}); import beamsim"
    p = subprocess.run([sys.executable, "-S", "-c", code], capture_output=True, text=True)
    assert p.returncode == 1
    last = p.stderr.strip().splitlines()[-1]
    assert last.startswith("ImportError: beamsim needs NumPy, which this Python ("), last
    assert f"run {_built.python}, the Python beamsim was built for" in last, last
