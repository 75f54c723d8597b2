"""``python -m meshvae_lib.cli``: run one command and exit with its status.

After a Ctrl-C has been reported (status 130), further interrupts are ignored: the command is over,
and a late second one (while the interpreter shuts down) must not turn the status into a death by
SIGINT or print a traceback.
"""

import signal
import sys

from meshvae_lib.cli import EXIT_INTERRUPTED, main

try:
    status = main()
except KeyboardInterrupt:  # a second Ctrl-C while the first was being reported
    print("meshvae: interrupted", file=sys.stderr)
    status = EXIT_INTERRUPTED
if status == EXIT_INTERRUPTED:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
sys.exit(status)
