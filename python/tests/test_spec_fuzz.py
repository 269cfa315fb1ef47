"""Bounded, seeded fuzzing of the sweep-spec reader (`python -m irpol.dataset`, docs/design.md
§2.7), the one reader of user files written in Python: mutations of a render spec and a fit spec
(bytes replaced, inserted and deleted, lines swapped, runs of thousands of one character) must give
a spec or a `SpecError`/`OSError` whose message is one line of at most a few hundred printable
characters — never another exception. `SPEC_FUZZ_CASES` and `SPEC_FUZZ_SEED` (environment) fuzz
longer or elsewhere."""

from __future__ import annotations

import os
import random
import shutil
from pathlib import Path

from irpol.dataset import SpecError
from irpol.dataset.spec import load_spec
from conftest import ROOT, cli_output

CASES = int(os.environ.get("SPEC_FUZZ_CASES", "1500"))
SEED = int(os.environ.get("SPEC_FUZZ_SEED", "20261127"))

RENDER_SPEC = (ROOT / "examples" / "sweep_car_day.toml").read_bytes().replace(
    b"../scenes/car_day.toml", b"scene.toml")
FIT_SPEC = (b'kind = "fit"\ninputs = "measurements/*.csv"\nout = "fits"\n'
            b'[options]\ndistribution = "cauchy"\nseed = 3\nfree = ["sigma", "n"]\n')
PIECES = [b"=", b"[", b"]", b"{", b"}", b'"', b",", b"\n", b"#", b".", b"-1e400", b"nan",
          b"\x00", b"\x1b[31m", b"\xff", b"[grid]", b"kind", b"time_s", b"camera.position",
          b"'''", b"\r\n"]


def _mutate(rng: random.Random, data: bytes) -> bytes:
    data = bytearray(data)
    for _ in range(rng.randint(1, 6)):
        at = rng.randint(0, len(data))
        choice = rng.random()
        if choice < 0.3 and data:
            del data[at:at + rng.randint(1, 40)]
        elif choice < 0.5:
            data[at:at] = rng.choice(PIECES)
        elif choice < 0.6:
            data[at:at] = bytes([rng.choice(b"a1\"[.!")]) * rng.randint(500, 5000)
        elif choice < 0.8 and data:
            data[min(at, len(data) - 1)] = rng.randint(0, 255)
        else:
            lines = bytes(data).split(b"\n")
            rng.shuffle(lines)
            data = bytearray(b"\n".join(lines))
    return bytes(data)


def _check_message(error: BaseException) -> None:
    message = str(error)
    assert "\n" not in message and len(message) < 800, repr(message[:300])
    assert not any(ord(c) < 32 or 0x7f <= ord(c) < 0xa0 for c in message), repr(message)


def test_the_spec_reader_never_fails_unexpectedly(tmp_path):
    cli_output("scene", "init", "--out", tmp_path / "scene.toml")
    (tmp_path / "measurements").mkdir()
    shutil.copy(ROOT / "measurements" / "paper_paint.csv", tmp_path / "measurements")
    rng = random.Random(SEED)
    spec = tmp_path / "spec.toml"
    read = 0
    for case in range(CASES):
        spec.write_bytes(_mutate(rng, rng.choice([RENDER_SPEC, FIT_SPEC])))
        try:
            load_spec(spec).items()
            read += 1
        except (SpecError, OSError) as e:
            _check_message(e)
        except Exception as e:  # noqa: BLE001 - the point: nothing else may escape
            raise AssertionError(f"case {case}: {type(e).__name__}: {e!s:.300}\n"
                                 f"spec: {spec.read_bytes()[:600]!r}") from e
    assert read > CASES // 50, f"only {read} of {CASES} mutated specs were valid: seeds too broken"
