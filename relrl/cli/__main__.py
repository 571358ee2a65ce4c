"""``python -m relrl.cli`` is the ``relrl`` command."""

import sys

from relrl.cli import main

sys.exit(main())
