"""The one exception type of the project.

Every function that can fail on user input raises :class:`ColonsimError` with a message that
names the problem and the fix. The command line turns it into one line and exit code 2.
"""


class ColonsimError(ValueError):
    """Bad user input or an unrecoverable simulation state, with an actionable message."""
