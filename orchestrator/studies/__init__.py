"""Studies: many runs of a scene and what they say together.

`jobs` runs scenes in parallel (process pool or Dask); `parameter_sweep`,
`tolerance_study` (with `study_table`, `sampling`, `study_statistics`, `study_report`),
`work_precision`, `stability`, `benchmarks` and `crosscheck` are built on it or
on single runs.
"""
