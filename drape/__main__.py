"""``python -m drape COMMAND``: the ``drape`` command (:func:`drape.cli.main`)."""
import sys

from drape.cli import main

sys.exit(main())
