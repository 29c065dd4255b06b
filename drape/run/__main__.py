"""``python -m drape.run CASE``: the ``drape run`` command (:func:`drape.cli.run.main`)."""
import sys

from drape.cli.run import main

sys.exit(main())
