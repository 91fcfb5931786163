"""The progress bar of runs and studies."""

from __future__ import annotations

from tqdm import tqdm


class ProgressBar(tqdm):
    """A tqdm bar without tqdm's monitor thread.  Our callers update their bars themselves
    (runs every 0.2 s, studies at each sample), and a process with no thread of its own
    can fork its sweep workers (studies/jobs.py), which then start with every module
    imported instead of importing them again."""

    monitor_interval = 0
