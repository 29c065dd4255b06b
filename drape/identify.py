"""``python -m drape.identify``: the ``drape identify`` command (:func:`drape.cli.identify.main`)."""
import sys

if __name__ == "__main__":
    # under the guard: importing drape.identify loads no command line
    from drape.cli.identify import main

    sys.exit(main())
