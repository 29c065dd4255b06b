"""The models' input errors: each message names the parameter and the rule it breaks."""

__all__ = ["ShellInputError", "PlateInputError"]


class ShellInputError(ValueError):
    """Invalid input to the large-rotation shell model."""


class PlateInputError(ValueError):
    """Invalid plate-model input; the message names the parameter and the rule it breaks."""
