"""The master: scenario loading, FMU loading, coupling, events, recording, reports, CLI."""
