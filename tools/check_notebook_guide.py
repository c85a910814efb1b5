"""Run every ```python block of a guide (docs/notebooks.md), in order, in one namespace, with
OUT set to a run's output folder: the guide's code must work as printed.

Usage: python tools/check_notebook_guide.py docs/notebooks.md OUT
"""
import re
import sys


def main() -> int:
    guide, out = sys.argv[1], sys.argv[2]
    text = open(guide, encoding="utf-8").read()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    if not blocks:
        print(f"{guide}: no python blocks", file=sys.stderr)
        return 1
    namespace: dict = {}
    for k, code in enumerate(blocks, 1):
        code = re.sub(r'^OUT = ".*"$', f"OUT = {out!r}", code, flags=re.M)
        print(f"--- block {k} of {len(blocks)}")
        exec(compile(code, f"{guide} block {k}", "exec"), namespace)
    print(f"ok: {len(blocks)} blocks of {guide} ran against {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
