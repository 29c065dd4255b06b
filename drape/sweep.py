"""``python -m drape.sweep``: the ``drape sweep`` command (:func:`drape.batch.sweep_cli.main`)."""
import sys

if __name__ == "__main__":
    from drape.batch.sweep_cli import main

    sys.exit(main())
