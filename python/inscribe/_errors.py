"""inscribe.Error: every failure that is neither a bad argument nor a missing file."""


class Error(Exception):
    """A failed inscribe call. ``code`` names the status code as gRPC and absl spell it
    ("FAILED_PRECONDITION", "RESOURCE_EXHAUSTED", "UNAVAILABLE", ...); the message is the
    core's or the server's, unchanged. In-process calls raise ValueError for INVALID_ARGUMENT
    and FileNotFoundError for NOT_FOUND instead; the service client raises ValueError for
    INVALID_ARGUMENT and this class (code "NOT_FOUND") for unknown keys."""

    def __init__(self, message: str, code: str):
        super().__init__(message)
        self.code = code

    def __repr__(self) -> str:
        return f"inscribe.Error({self.code}: {self.args[0]!r})"
