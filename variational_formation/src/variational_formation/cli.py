"""What every script of the package does on bad input."""
import os
import sys


def fail(message):
    """One line on stderr, named after the running script, and exit status 2."""
    program = os.path.splitext(os.path.basename(sys.argv[0]))[0]
    print(f"{program}: error: {' '.join(str(message).split())}", file=sys.stderr)
    sys.exit(2)


def description(doc):
    """The first paragraph of a script's docstring, whole, for argparse's --help."""
    return " ".join(doc.strip().split("\n\n")[0].split())
