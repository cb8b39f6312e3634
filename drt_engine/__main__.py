"""``python -m drt_engine ...``: the headless command line (see headless/cli.py)."""
from .headless.cli import exit_now, main

exit_now(main())
