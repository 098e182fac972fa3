"""``python -m arzsumo``: the ``arzsumo`` command."""

import sys

from arzsumo.cli import main

if __name__ == "__main__":
    sys.exit(main())
