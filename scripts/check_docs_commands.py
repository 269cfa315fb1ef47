#!/usr/bin/env python3
"""Every documented command leaves the repository clean.

Extracts each `irpol …`, `cargo run --release -- …` and `target/release/irpol …` command from
the shell code blocks (``` with no language, sh, bash, shell or console) of README.md and
docs/*.md, and runs them, file by file in the order written, in a fresh `git clone` of the
repository (its committed state) in a temporary folder, with `irpol` being the built binary
(default target/release/irpol; nothing is compiled). A command fails the check when it exits
non-zero, runs longer than --timeout seconds, or leaves `git status --porcelain` non-empty.

Also run, in blocks that hold a command: the set-up lines a reader copies with it (mkdir, cp,
cat, ln). Not run: usage synopses (`<FILE>`, `[--flag]`, `A | B`) and the commands listed in
SKIPPED below, each with its reason. Saved thermal runs (out/thermal/) are carried from one
file's clone to the next, as a reader's own checkout keeps them: the README and thermal.md tour
the same day, which is solved once.

Standard library only. Usage:
    scripts/check_docs_commands.py [--irpol target/release/irpol] [--list] [--timeout 150]
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent

# (pattern matched against the command as run, reason it is not run).
SKIPPED = [
    (r"^cargo build\b", "the build itself: the check runs the binary already built"),
    (r"^cargo test\b", "the test suite: .ci/run runs it as its own step"),
    (r"^cargo bench\b", "benchmarks: minutes each, numbers in docs/verification.md"),
    (r"^cargo install\b", "installs into ~/.cargo/bin, outside the clone: the same binary"),
    (r"^cargo run --release --example\b", "examples write the shipped figures in docs/images/"),
    (r"^irpol demo\b", ".ci/run runs the demo first and checks git status after it"),
    (r"\bpip install\b|-m venv\b", "needs the network (PyPI); .ci/run builds the Python package"),
    (r"^export PATH=", "changes the reader's shell only"),
    (r"\bmy_data/", "an example for a folder of the reader's own (my_data/), not shipped"),
    (
        r"^irpol fit measurements/? --out fits( --reports \S+)?$",
        "regenerates the shipped library in place, as documented: its last digits follow the CPU",
    ),
    (
        r"^irpol fit out/smooth_glass\.pbsdf\b",
        "fits a whole exported table (5 wavelengths × ~10 000 nodes): about 90 s on 2 cores",
    ),
    (
        r"^irpol thermal scenes/car_terrain_day\.toml",
        "2.56 M vertices: about 2 min and 1.7 GB on 2 cores (docs/verification.md)",
    ),
    (
        r"^irpol render scenes/car_terrain\.toml",
        "5 M triangles at 1080p: 1.7 GB (docs/verification.md); the car scenes are run",
    ),
]

SHELL_LANGUAGES = {"", "sh", "bash", "shell", "console"}
SETUP_WORDS = {"mkdir", "cp", "cat", "ln"}
SYNOPSIS = re.compile(r"<[A-Za-z]|\[--|\[[A-Z]|\s\|\s|\.\.\.|…")
# A word in capitals standing for the reader's own value: SCENE.toml, SECONDS, FILE.
PLACEHOLDER = re.compile(r"^[A-Z][A-Z_]{2,}(\.[a-z]+)?$")


def code_blocks(text):
    """(first line number, language, lines) of each fenced code block."""
    blocks, current, language, start = [], None, "", 0
    for number, line in enumerate(text.splitlines(), 1):
        fence = line.strip()
        if fence.startswith("```"):
            if current is None:
                current, language, start = [], fence[3:].strip().lower(), number + 1
            else:
                blocks.append((start, language, current))
                current = None
        elif current is not None:
            current.append(line)
    return blocks


def logical_lines(lines):
    """Lines with backslash continuations joined, a leading `$ ` prompt removed."""
    joined, pending = [], ""
    for line in lines:
        line = line.rstrip()
        if line.endswith("\\"):
            pending += line[:-1] + " "
            continue
        line = (pending + line).strip()
        pending = ""
        if line.startswith("$ "):
            line = line[2:]
        if line:
            joined.append(line)
    return joined


def as_irpol(line):
    """The line with `cargo run --release --` or `target/release/irpol` as `irpol`."""
    for prefix in ("cargo run --release -- ", "target/release/irpol ", "./target/release/irpol "):
        if line.startswith(prefix):
            return "irpol " + line[len(prefix):]
    return line


def skip_reason(command):
    for pattern, reason in SKIPPED:
        if re.search(pattern, command):
            return reason
    return None


def without_comment(line):
    """The command without a trailing `# …` comment (outside quotes)."""
    quote = None
    for i, c in enumerate(line):
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip()
    return line


def commands_of(path):
    """[(line number, command, skip reason or None)] of the file's shell blocks."""
    found = []
    for start, language, lines in code_blocks(path.read_text(encoding="utf-8")):
        if language not in SHELL_LANGUAGES:
            continue
        block = [as_irpol(without_comment(line)) for line in logical_lines(lines)]
        block = [line for line in block if line]
        is_command = [
            line.startswith("irpol ") or line == "irpol" or line.startswith("cargo ")
            for line in block
        ]
        if not any(is_command):
            continue
        for offset, line in enumerate(block):
            first = line.split()[0]
            if first != "irpol" and first != "cargo" and first not in SETUP_WORDS:
                if not line.startswith("export ") and "pip install" not in line:
                    continue
            words = re.split(r"[\s=]+", line)
            if first in ("irpol", "cargo") and (
                SYNOPSIS.search(line) or any(PLACEHOLDER.match(w) for w in words)
            ):
                continue
            # Set-up lines keep && chains whole: `mkdir -p out && cp …`.
            found.append((start + offset, line, skip_reason(line)))
    return found


def run(command, cwd, env, timeout):
    started = time.monotonic()
    try:
        done = subprocess.run(
            ["bash", "-c", command], cwd=cwd, env=env, timeout=timeout,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        )
        ok, output = done.returncode == 0, done.stdout
    except subprocess.TimeoutExpired as expired:
        ok, output = False, f"timed out after {timeout} s\n{expired.stdout or ''}"
    return ok, output, time.monotonic() - started


def dirty(clone):
    status = subprocess.run(
        ["git", "status", "--porcelain"], cwd=clone, stdout=subprocess.PIPE, text=True, check=True
    )
    return status.stdout.rstrip()


def check_file(doc, commands, workdir, env, timeout, runs_from):
    """Runs `commands` of `doc` in a fresh clone; returns (failures, clone path)."""
    clone = workdir / doc.replace("/", "_")
    subprocess.run(["git", "clone", "-q", str(REPO), str(clone)], check=True)
    if runs_from is not None and (runs_from / "out/thermal").is_dir():
        shutil.copytree(runs_from / "out/thermal", clone / "out/thermal")
    failures = []
    for number, command, reason in commands:
        where = f"{doc}:{number}"
        if reason:
            print(f"  skip  {where}: {command}\n        ({reason})")
            continue
        ok, output, seconds = run(command, clone, env, timeout)
        status = dirty(clone)
        print(f"  {'ok' if ok and not status else 'FAIL':4}  {where}: {command}  [{seconds:.1f} s]")
        if not ok:
            failures.append(f"{where}: `{command}` failed:\n{output[-2000:]}")
        if status:
            failures.append(f"{where}: `{command}` left the clone dirty:\n{status}")
            subprocess.run(["git", "clean", "-qfd"], cwd=clone)
            subprocess.run(["git", "checkout", "-q", "."], cwd=clone)
    return failures, clone


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--irpol", default=str(REPO / "target/release/irpol"))
    parser.add_argument("--timeout", type=float, default=150.0, help="seconds per command")
    parser.add_argument("--list", action="store_true", help="list the commands, run nothing")
    args = parser.parse_args()

    docs = ["README.md"] + sorted(
        str(p.relative_to(REPO)) for p in (REPO / "docs").glob("*.md")
    )
    per_doc = [(doc, commands_of(REPO / doc)) for doc in docs]
    per_doc = [(doc, commands) for doc, commands in per_doc if commands]
    if args.list:
        for doc, commands in per_doc:
            for number, command, reason in commands:
                print(f"{doc}:{number}: {command}" + (f"   [skip: {reason}]" if reason else ""))
        return 0

    irpol = Path(args.irpol).resolve()
    if not os.access(irpol, os.X_OK):
        print(f"{irpol}: no irpol binary: build it first (cargo build --release)", file=sys.stderr)
        return 2
    started = time.monotonic()
    failures = []
    with tempfile.TemporaryDirectory(prefix="irpol-docs-") as tmp:
        workdir = Path(tmp)
        bin_dir = workdir / "bin"
        bin_dir.mkdir()
        (bin_dir / "irpol").symlink_to(irpol)
        env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}")
        previous = None
        for doc, commands in per_doc:
            print(f"== {doc} (a fresh clone)")
            found, previous = check_file(doc, commands, workdir, env, args.timeout, previous)
            failures += found
    print(f"== {time.monotonic() - started:.0f} s in all")
    if failures:
        print("\n".join(["", "FAILED:"] + failures), file=sys.stderr)
        return 1
    print("every documented command ran and left its clone clean")
    return 0


if __name__ == "__main__":
    sys.exit(main())
