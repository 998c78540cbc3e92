"""`python -m ocpkit.cli`: the `ocpkit` command."""

import sys

from ocpkit.cli.main import main

sys.exit(main())
