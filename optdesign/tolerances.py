"""The tolerances that decide what counts, in one place.

Every test of "is this design feasible", "is this row active" and "do these two
objective values tie" reads its tolerance here, so the solver's report, the independent
check, a front's records, the benchmark and the catalogue search cannot disagree on the
same point.
"""

from __future__ import annotations

#: A design is feasible when no requirement row is violated by more than this, relative
#: to max(1, |bound|) (the independent check, :func:`optdesign.formulations.verify.
#: verify_design`) or on the solver's scaled rows (:func:`optdesign.solvers.base.
#: constraint_reports`); a row within it of its bound is active, and so is a free
#: variable's bound within it (relative to max(1, upper - lower)) of the variable's value
#: (:func:`optdesign.display.limits.at_bound`, shared by the summary, the limits table
#: and a sweep's binding set).
FEASIBILITY_TOL = 1e-6

#: Two objective values tie when they differ by at most this, relative to the larger of
#: |value| and 1e-12: the multistart's agreement and best start, the catalogue search's
#: pruning and incumbent, the optimal set's ranges.
OBJECTIVE_TIE_TOL = 1e-6

#: A constraint row a solve left out (a solve on a subset of the rows: every other grid
#: angle) counts as met at that solve's point when it is within this of its bound on the
#: solver's scaled rows - the NLP back-ends' own constraint tolerance (Ipopt's
#: ``constr_viol_tol``), so the point is what a solve on every row could have returned
#: (:func:`optdesign.solvers.base.on_every_row`).
LEFT_OUT_ROW_TOL = 1e-9
