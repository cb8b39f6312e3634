"""``python -m drt_engine ...``: the headless command line (see cli.py)."""
import sys

from .cli import main

sys.exit(main())
