#!/usr/bin/env python3
"""Before/after check of a refactor: every table under two `out/` folders byte-identical.

    python3 tools/compare_out.py OUT_BEFORE OUT_AFTER [--rename OLD=NEW ...]

Compares each `tables/*.{csv,md,tex}` and the other CSV outputs (e.g. `estimates.csv`) of every
pipeline folder. `--rename` maps a pipeline folder name of the first tree to the second's (a
pipeline that was renamed). Ignored: `Provenance:` lines (they carry the git commit) and the
timing tables, which are measurements (`timing_*`). Prints one line per file and a closing
`N passed, N failed` line; `--only NAME` limits the check to some pipelines; exits 1 when anything differs or is missing.
"""
import argparse
import pathlib
import sys

MEASURED_PREFIXES = ("timing_",)


def normalised(path: pathlib.Path) -> list[str]:
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    return [l for l in lines if "Provenance:" not in l]


def table_files(root: pathlib.Path) -> list[pathlib.Path]:
    out = []
    for p in sorted(root.rglob("*")):
        rel = p.relative_to(root)
        if not p.is_file() or rel.parts[0] in ("datasets", ".tmp") or "sessions" in rel.parts:
            continue
        if p.suffix == ".csv" or (p.suffix in (".md", ".tex") and "tables" in rel.parts):
            if p.name.startswith(MEASURED_PREFIXES):
                continue
            out.append(rel)
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before", type=pathlib.Path)
    ap.add_argument("after", type=pathlib.Path)
    ap.add_argument("--rename", action="append", default=[], metavar="OLD=NEW")
    ap.add_argument("--only", action="append", default=[], metavar="NAME", help="compare only these pipeline folders (names in the first tree)")
    a = ap.parse_args()
    rename = dict(r.split("=", 1) for r in a.rename)
    passed = failed = 0
    seen_after = set()
    for rel in table_files(a.before):
        if a.only and rel.parts[0] not in a.only:
            continue
        target = pathlib.Path(rename.get(rel.parts[0], rel.parts[0]), *rel.parts[1:])
        seen_after.add(target)
        other = a.after / target
        if not other.exists():
            print(f"MISSING  {target}")
            failed += 1
        elif normalised(a.before / rel) != normalised(other):
            print(f"DIFFERS  {rel} -> {target}")
            failed += 1
        else:
            passed += 1
    only_after = {rename.get(o, o) for o in a.only}
    for rel in table_files(a.after):
        if a.only and rel.parts[0] not in only_after:
            continue
        if rel not in seen_after:
            print(f"NEW      {rel}")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
