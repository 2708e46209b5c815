"""The one exception type of the project.

Every function that can fail on user input raises :class:`ColonsimError` with a message that
names the problem and the fix. The command line turns it into one line and exit code 2.
"""


class ColonsimError(ValueError):
    """Bad user input or an unrecoverable simulation state, with an actionable message."""


class ColonsimWarning(UserWarning):
    """Input that is accepted but probably not meant (a wall softer than any tissue, a query outside
    the training domain): the command line prints it as one ``colonsim: warning:`` line."""
