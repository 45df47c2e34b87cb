"""The execution engine: tasks run in local worker processes or on a Dask cluster, with a
resumable store (:mod:`~optdesign.runtime.runner`), the worker processes themselves
(:mod:`~optdesign.runtime.processes`, :mod:`~optdesign.runtime.inherited_map`), where and
how a study's tasks run (:mod:`~optdesign.runtime.run_options`) and a stored run's
identity (:mod:`~optdesign.runtime.identity`). It knows no formulation and no study."""
