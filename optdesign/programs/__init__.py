"""Programs: a design problem written as the mathematical program a solver takes, below
the solvers that consume them.

- :mod:`optdesign.programs.nlp`: smooth NLP on CasADi (epigraph forms of the min-max
  objectives, scaled variables, exact derivatives; also the naive max/min form), with
  its bounds, starts and targets;
- :mod:`optdesign.programs.gp`: the geometric program (posynomial rows, first-order
  Hertz) and its cvxpy form; :mod:`optdesign.programs.signomial`: its algebra.

How a formulation uses them - the multistart, the catalogue search, the robust SAA - is
in :mod:`optdesign.formulations`.
"""
