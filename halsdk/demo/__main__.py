"""``python -m halsdk.demo``: the same as ``halsdk-demo``."""

import sys

from halsdk.demo import main

sys.exit(main())
