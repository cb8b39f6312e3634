"""What a kernel cache folder holds, read from Numba's index files."""
from __future__ import annotations

import pickle
from pathlib import Path


def kernel_cpus(folder: Path) -> set[str]:
    """The CPU names the entries under ``folder`` were compiled for (an index file is Numba's
    version, then the source stamp and {(signature, (triple, cpu, features), hashes): data file})."""
    cpus = set()
    for index in Path(folder).rglob("*.nbi"):
        with open(index, "rb") as f:
            pickle.load(f)
            _, overloads = pickle.loads(f.read())
        cpus.update(key[1][1] for key in overloads)
    return cpus
