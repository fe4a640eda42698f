"""``python -m halcompile``: the halcompile command."""

import sys

from halcompile.cli import main

sys.exit(main())
