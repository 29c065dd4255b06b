"""``python -m constitutive.fit``: the ``drape fit`` command (:func:`drape.cli.fit.main`)."""
import sys

from drape.cli.fit import main

sys.exit(main())
