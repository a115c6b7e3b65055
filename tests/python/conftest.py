"""Shared fixtures of the Python module's tests: the repository, the command line and a runner.

ctest sets PYTHONPATH to the built module and IMSCAL_BINARY, IMSCAL_SOURCE_DIR
(tests/CMakeLists.txt); by hand: PYTHONPATH=build/python IMSCAL_BINARY=build/tools/imscal
python3 -m pytest tests/python.
"""
import os
import pathlib
import subprocess

import pytest


@pytest.fixture(scope="session")
def repo():
    return pathlib.Path(os.environ.get("IMSCAL_SOURCE_DIR", pathlib.Path(__file__).parents[2]))


@pytest.fixture(scope="session")
def cli(repo):
    """Runs `imscal ARGS...`; returns the completed process (stdout, stderr as text)."""
    binary = os.environ.get("IMSCAL_BINARY", str(repo / "build" / "tools" / "imscal"))

    def run(*args, expect=0):
        done = subprocess.run([binary, *map(str, args)], capture_output=True, text=True)
        assert done.returncode == expect, done.stderr
        return done

    return run
