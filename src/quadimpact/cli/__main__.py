"""``python -m quadimpact.cli``: the ``quadimpact`` command."""

from quadimpact.cli import main

main()
