"""Master algorithms, by the name a scene gives its ``master.algorithm``.

``registry.ALGORITHMS`` holds each algorithm's typed settings (orchestrator/master_settings.py)
and its factory, which makes the master of one run from its settings and the coupled
system; the execution loop (orchestrator/execution.py) steps it.  This package imports no
master itself: the scene loader reads the registry without them.
"""
