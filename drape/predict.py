"""``python -m drape.predict``: the ``drape predict`` command (:func:`drape.cli.predict.main`)."""
import sys

if __name__ == "__main__":
    # under the guard: importing drape.predict loads no command line
    from drape.cli.predict import main

    sys.exit(main())
