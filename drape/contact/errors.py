"""The one error of contact input: a body, its file or its path that cannot be used."""

__all__ = ["ContactInputError"]


class ContactInputError(ValueError):
    """A contact body, surface file or rigid path that cannot be used (message: one line)."""
