"""The global search: where local solves start, when they stop, and the odds of a better
optimum (:mod:`~optdesign.search.starts`, :mod:`~optdesign.search.global_phase`,
:mod:`~optdesign.search.odds`). Every formulation, front and sweep that looks for a
global optimum goes through it; it knows the problem's NumPy model and a local solver's
``x0 -> Result``, no formulation and no back-end."""
