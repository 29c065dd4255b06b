"""``python -m drape.validate``: the ``drape validate`` command (:func:`drape.batch.validation_set.main`)."""
import sys

if __name__ == "__main__":
    from drape.batch.validation_set import main

    sys.exit(main())
