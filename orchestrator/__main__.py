"""``python -m orchestrator``: the ``mechcosim`` command."""

from orchestrator.entry import command

command()
