"""Shared fixtures: the `cdbo` command-line binary the Python results are checked against."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def cli():
    """Runs `cdbo ARGS...` and returns its stdout: the binary in $CDBO_BIN (CI sets it; a
    missing one is an error), else target/release/cdbo if it was built, else the test is
    skipped."""
    env = os.environ.get("CDBO_BIN")
    if env:
        binary = pathlib.Path(env)
        assert binary.is_file(), f"CDBO_BIN={env} does not exist"
    else:
        binary = REPO / "target" / "release" / "cdbo"
        if not binary.is_file():
            pytest.skip("no cdbo binary: build it with `cargo build --release` or set CDBO_BIN")

    def run(*args, cwd=None):
        done = subprocess.run(
            [str(binary), *map(str, args)], capture_output=True, text=True, cwd=cwd
        )
        assert done.returncode == 0, f"cdbo {' '.join(map(str, args))}: {done.stderr}"
        return done.stdout

    return run
