"""Make the repository root importable so ``import drt_engine`` and ``from tests.support import ...`` work from any test.

tests/real_blender needs the Debian root with a real Blender: only ``make test-blender``
collects it (it sets DRT_BLENDER_ENV); ``make test`` leaves it out.
"""
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

collect_ignore = [] if os.environ.get("DRT_BLENDER_ENV") else ["real_blender"]
