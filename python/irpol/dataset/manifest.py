"""``out/manifest.jsonl``: one JSON line per finished item, written by the driver alone."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Dict, List

from .items import hashes, item_folder
from .spec import Item


def read_rows(path: Path) -> List[dict]:
    """The manifest's rows; a line cut short by a crash is dropped."""
    if not path.exists():
        return []
    rows = []
    for line in path.read_text().splitlines():
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return rows


def _finished(row: dict, item: Item, out: Path) -> bool:
    """An ok row for this item's parameters whose files are on disk with the recorded hashes."""
    folder = item_folder(out, item.index)
    return (row.get("status") == "ok" and row.get("params") == item.params
            and folder.is_dir() and hashes(folder) == row.get("outputs"))


class Manifest:
    def __init__(self, out: Path):
        self.path = out / "manifest.jsonl"

    def finished(self, items: List[Item], out: Path) -> Dict[int, dict]:
        """The rows of the items that need no work, and the manifest rewritten to hold only
        them (failed, stale or duplicate rows are dropped, so a complete run ends with exactly
        one row per item)."""
        by_index = {item.index: item for item in items}
        rows = read_rows(self.path)
        kept: Dict[int, dict] = {}
        for row in rows:
            item = by_index.get(row.get("item"))
            if item is not None and row["item"] not in kept and _finished(row, item, out):
                kept[row["item"]] = row
        if len(kept) != len(rows) or self._has_partial_line():
            self._rewrite(list(kept.values()))
        return kept

    def _has_partial_line(self) -> bool:
        return self.path.exists() and not self.path.read_bytes().endswith(b"\n") \
            and self.path.stat().st_size > 0

    def _rewrite(self, rows: List[dict]) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        temporary = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")
        with open(temporary, "w") as f:
            f.writelines(json.dumps(r) + "\n" for r in rows)
            f.flush()
            os.fsync(f.fileno())
        os.replace(temporary, self.path)

    def append(self, row: dict) -> None:
        with open(self.path, "a") as f:
            f.write(json.dumps(row) + "\n")
            f.flush()
            os.fsync(f.fileno())
