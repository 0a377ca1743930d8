"""``python -m turntable_pin`` runs the command line."""

import sys

from .cli import main

sys.exit(main())
