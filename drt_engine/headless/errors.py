"""The CLI's one error and its exit codes, apart from the parser: every headless module raises
CLIError and none of them imports cli.py."""

EXIT_ERROR = 1
EXIT_USAGE = 2


class CLIError(Exception):
    """Bad input: the message is the one line the user sees."""

    def __init__(self, message: str, code: int = EXIT_ERROR):
        super().__init__(message)
        self.code = code
