"""``python -m halsdk.demo``"""

import sys

from halsdk.demo import main

sys.exit(main())
