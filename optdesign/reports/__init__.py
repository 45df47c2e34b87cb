"""Reading results: text tables for the terminal, pandas frames, HTML reports.

Every module here reads typed results (:class:`~optdesign.solvers.result.Result`,
:class:`~optdesign.studies.pareto.Front`) and the problem's declarations (units,
descriptions); none computes a result.
"""
