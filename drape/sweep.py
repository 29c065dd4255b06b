"""``python -m drape.sweep``: the ``drape sweep`` command (:func:`drape.batch.sweep.main`)."""
import sys

if __name__ == "__main__":
    from drape.batch.sweep import main

    sys.exit(main())
