"""``python -m drape.inspect``: the ``drape inspect`` command (:func:`drape.run.pictures.main`)."""
import sys

if __name__ == "__main__":
    from drape.run.pictures import main

    sys.exit(main())
