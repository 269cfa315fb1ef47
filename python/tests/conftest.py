"""Shared helpers: the repository root, the `irpol` binary the Python results are compared with
(`IRPOL_BIN`, default target/release/irpol), and numbers reported at the end of the run."""

from __future__ import annotations

import os

# OpenBLAS's worker threads spin after a call and would take the cores the timed code needs
# (test_speed); nothing here gains from threaded BLAS.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import csv
import io
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
IRPOL = Path(os.environ.get("IRPOL_BIN", ROOT / "target" / "release" / "irpol"))
REPORTED: list[str] = []


def report(line: str) -> None:
    """A number worth seeing in the run's output (speed ratios, sweep timings)."""
    REPORTED.append(line)


def pytest_terminal_summary(terminalreporter):
    if REPORTED:
        terminalreporter.section("irpol numbers")
        for line in REPORTED:
            terminalreporter.write_line(line)


def run_cli(*args, cwd=ROOT) -> subprocess.CompletedProcess:
    if not IRPOL.is_file():
        pytest.fail(f"{IRPOL} is missing: run `cargo build --release` first (or set IRPOL_BIN)")
    return subprocess.run([str(IRPOL), *map(str, args)], cwd=cwd, capture_output=True, text=True)


def cli_output(*args, cwd=ROOT) -> str:
    done = run_cli(*args, cwd=cwd)
    assert done.returncode == 0, done.stderr
    return done.stdout


def cli_error(*args, cwd=ROOT) -> str:
    """The one-line message of a failing command, without the `irpol: error: ` prefix."""
    done = run_cli(*args, cwd=cwd)
    assert done.returncode != 0, done.stdout
    lines = [l for l in done.stderr.splitlines() if l.startswith("irpol: error: ")]
    assert len(lines) == 1, done.stderr
    return lines[0][len("irpol: error: "):]


def csv_table(text: str) -> tuple[list[str], np.ndarray]:
    """A CLI CSV (# lines skipped) as its header and a float64 array, each field parsed at full
    precision (the CLI prints shortest round-trip forms, so parsing gives the exact double)."""
    rows = list(csv.reader(l for l in io.StringIO(text) if not l.startswith("#")))
    return rows[0], np.array([[float(x) for x in row] for row in rows[1:]], dtype=np.float64)


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT
