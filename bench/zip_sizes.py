"""Sizes of the extension zips in dist/ and of the numba + llvmlite wheels inside them.

`make extension` prints the table; `python bench/zip_sizes.py --publish` also writes it into
docs/install.md between its markers, so the sizes there are the ones measured, not typed.
"""
import argparse
import re
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench.blocks import write_block  # noqa: E402
NOTES = {"macos_arm64": " (PyPI has no embreex 4.4 wheel for Intel Macs)"}


def table(dist: Path) -> str:
    rows = ["| zip | size | of which numba + llvmlite, both Pythons | of which compiled kernels, compressed (tools/ship_kernels.py) |",
            "|---|---|---|---|"]
    zips = sorted(dist.glob("drt_engine-*.zip"))
    if not zips:
        sys.exit(f"error: no extension zips in {dist}: run make extension first")
    for path in zips:
        with zipfile.ZipFile(path) as z:
            compiled = sum(i.file_size for i in z.infolist() if re.search(r"/(numba|llvmlite)-", i.filename))
            kernels = sum(i.compress_size for i in z.infolist() if i.filename.startswith("kernels/"))
        platform = path.stem.rsplit("-", 1)[1]
        rows.append(f"| `dist/{path.name}`{NOTES.get(platform, '')} | {path.stat().st_size / 1e6:.0f} MB "
                    f"| {compiled / 1e6:.0f} MB | {f'{kernels / 1e6:.0f} MB' if kernels else 'none'} |")
    return "\n".join(rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--dist", type=Path, default=ROOT / "dist")
    parser.add_argument("--publish", action="store_true", help="write the table into docs/install.md")
    args = parser.parse_args()
    text = table(args.dist)
    print(text)
    if args.publish:
        write_block("zip-sizes", text)


if __name__ == "__main__":
    main()
