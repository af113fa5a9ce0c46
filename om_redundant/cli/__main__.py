"""``python -m om_redundant.cli``: the ``om-redundant`` command."""

import sys

from . import main

sys.exit(main())
