"""The root of navlab's errors; each package derives its own (``DescriptionError``, ``WorldError``, ...).

The CLI prints a ``NavlabError`` as one line (``navlab: error: ...``) instead of a traceback, so
its message must name the file, element or key and say what was expected.
"""


class NavlabError(Exception):
    """Base class of every error navlab raises on purpose."""
