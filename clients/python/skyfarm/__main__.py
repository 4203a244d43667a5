"""``python3 -m skyfarm``: the CLI, also from the source tree
(``PYTHONPATH=clients/python``)."""

import sys

from .cli import main

sys.exit(main())
