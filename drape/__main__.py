"""``python -m drape COMMAND``: the ``drape`` command (:func:`drape.commands.main`)."""
import sys

from drape.commands import main

sys.exit(main())
