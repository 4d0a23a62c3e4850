"""`python -m cotm_bertini.cli`: the same as the `cotm-bertini` command."""

import sys

from .main import main

sys.exit(main())
