"""``python -m drt_engine ...``: the headless command line (see cli.py)."""
from .cli import exit_now, main

exit_now(main())
