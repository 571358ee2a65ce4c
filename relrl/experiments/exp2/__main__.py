"""``python -m relrl.experiments.exp2``: Experiment 2's sweep (:func:`.sweep.main`)."""

import sys

from relrl.experiments.exp2.sweep import main

sys.exit(main())
