"""``python -m drape.identify``: the ``drape identify`` command (:func:`drape.identification.cli.main`)."""
import sys

if __name__ == "__main__":
    from drape.identification.cli import main

    sys.exit(main())
