"""The single exception type of gearshot."""

__all__ = ["GearshotError"]


class GearshotError(ValueError):
    """Raised on invalid input or an unusable file.

    Subclasses :class:`ValueError` so that callers who already guard numeric code with
    ``except ValueError`` keep working. Messages name the offending parameter (or file)
    and quote the bad value.
    """
