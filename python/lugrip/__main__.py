"""``python -m lugrip``: the lugrip command line."""

import sys

from .cli import main

sys.exit(main())
