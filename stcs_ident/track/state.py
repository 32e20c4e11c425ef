"""What a rerun of ``track`` has to do: the archive as it is now against the rows of the parts.

A row's slot is its record's place in the archive: the cable and the path
below the cable's folder. A row is current when it holds the content now at
its slot (``record_id``, the SHA-256 of the file) as processed under the
cable's current ``version`` (a hash of the cable's campaign as parsed, the
settings that shape a row and the toolkit's version) and its status is
``ok``. Then, per slot of the archive:

- **unchanged**: a current row; its file is not hashed again when its size and
  modification time are those of the row;
- **new** (no row at that path), **changed** (a row of another content) or
  **stale** (a row of the same content under another version): processed,
  unless the cable has a current row of the same content at another path
  (a record copied or renamed), which is reused;
- **retried**: a row that failed is processed again on every run (what made
  it fail may be gone: a file being copied, a path a worker could not see).

A new slot is hashed here only when the cable has a current row of a file of
its size (it may be a copy); otherwise its worker hashes it while reading it
for the record (``record_id`` "" in the plan), and the run's row at that
path is the slot's. The first run over an archive so reads each file once,
in the workers, not once serially here and again there.

A row whose path is no longer in the archive is **removed** from the table
(its record is gone; the rows are never marked and kept). The table is so a
function of the archive and the campaigns: the same as a first run on the
archive as it now is.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd

from .archive import CableSpec, content_id, record_paths

__all__ = ["COUNTS", "CablePlan", "current_rows", "plan_cable"]

#: What a run did, in the order of its summary line.
COUNTS = ("new", "changed", "stale", "removed", "retried", "unchanged")


@dataclass
class CablePlan:
    """One cable's slots now: ``slots`` {path: (record id or "" when its worker hashes it, size, mtime_ns)},
    the records to process
    (``pending``: (absolute path, record id, size, mtime_ns)), the counts of :data:`COUNTS`, and whether
    its parts need rewriting (``dirty``: rows to drop, reuse or update)."""

    spec: CableSpec
    slots: dict[str, tuple[str, int, int]] = field(default_factory=dict)
    pending: list[tuple[str, str, int, int]] = field(default_factory=list)
    counts: dict[str, int] = field(default_factory=lambda: dict.fromkeys(COUNTS, 0))
    dirty: bool = False


def plan_cable(spec: CableSpec, known: pd.DataFrame) -> CablePlan:
    """The plan of one cable from its rows in the parts (``known``: oldest first)."""
    plan = CablePlan(spec)
    mine = known[known["cable"] == spec.name]
    by_slot: dict[str, list] = {}
    for row in mine.itertuples(index=False):
        by_slot.setdefault(row.record, []).insert(0, row)  # latest first
    current = [r for r in mine.itertuples(index=False) if r.version == spec.version and r.status == "ok"]
    reusable = {r.record_id for r in current}
    sizes = {int(r.size_bytes) if pd.notna(r.size_bytes) else -1 for r in current}  # -1: a row of unknown size
    for path in record_paths(spec):
        st = path.stat()
        relative = path.relative_to(spec.directory).as_posix()
        rows = by_slot.get(relative, [])
        if not rows and -1 not in sizes and st.st_size not in sizes:  # new; no current row can be its content
            plan.slots[relative] = ("", int(st.st_size), int(st.st_mtime_ns))
            plan.counts["new"] += 1
            plan.dirty = True
            plan.pending.append((str(path), "", int(st.st_size), int(st.st_mtime_ns)))
            continue
        cached = next((r.record_id for r in rows if r.size_bytes == st.st_size and r.mtime_ns == st.st_mtime_ns), None)
        record_id = cached or content_id(path)
        plan.slots[relative] = (record_id, int(st.st_size), int(st.st_mtime_ns))
        same = [r for r in rows if r.record_id == record_id and r.version == spec.version]
        if same and same[0].status == "ok":
            plan.counts["unchanged"] += 1
            plan.dirty |= cached is None or len(rows) > 1  # a new time stamp to keep, or older rows to drop
            continue
        kind = ("retried" if same else "stale" if any(r.record_id == record_id for r in rows)
                else "changed" if rows else "new")
        plan.counts[kind] += 1
        plan.dirty = True
        if kind != "retried" and record_id in reusable:
            continue  # the same content elsewhere in the cable, processed under this version: its row serves
        plan.pending.append((str(path), record_id, int(st.st_size), int(st.st_mtime_ns)))
    gone = set(by_slot) - set(plan.slots)
    plan.counts["removed"] = len(gone)
    plan.dirty |= bool(gone)
    return plan


def current_rows(plan: CablePlan, known: pd.DataFrame) -> pd.DataFrame:
    """The cable's table: per slot of the archive its current row (the latest written), a row of the same
    content and version reused at a new path, else none (a record not processed: the run was stopped)."""
    spec = plan.spec
    mine = known[(known["cable"] == spec.name) & (known["version"] == spec.version)]
    latest = {}
    for label, record, record_id in zip(mine.index, mine["record"], mine["record_id"]):
        latest[(record, record_id)] = label
    by_content = {record_id: label for label, record_id, status in zip(mine.index, mine["record_id"], mine["status"])
                  if status == "ok"}
    at_path = dict(zip(mine["record"], mine.index))  # the latest row of this version at each path
    labels, slots = [], []
    for relative, (record_id, size, mtime) in plan.slots.items():
        if not record_id:  # hashed by its worker: a new slot, so its row at that path is this run's
            label = at_path.get(relative)
        else:
            label = latest.get((relative, record_id), by_content.get(record_id))
        if label is not None:
            labels.append(label)
            slots.append((relative, size, mtime))
    rows = known.loc[labels].copy()
    rows["record"] = [s[0] for s in slots]
    rows["size_bytes"] = [s[1] for s in slots]
    rows["mtime_ns"] = [s[2] for s in slots]
    return rows.reset_index(drop=True)
