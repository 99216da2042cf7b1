"""``python -m softarm.validation [--out DIR]``: the same as ``softarm reproduce``."""

import sys

from . import main

sys.exit(main())
