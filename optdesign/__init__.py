"""optdesign: design optimisation of ball-screw actuator transmissions.

Internal unit system (every number inside the package): millimetre (mm), newton (N),
megapascal (MPa = N/mm^2), newton-millimetre (N*mm) for moments, radian (rad) for angles.
Output backlash is *reported* in degrees. Quantities with units are accepted at the input
boundary (problem files, CLI) and converted by :mod:`optdesign.units`.

Data flow, one package per stage::

    models/       pure functions -> CasADi expressions or NumPy arrays (one definition each)
    mechanisms/   crank-slider and shifting fork: geometry + loads + clearance chain
    problem/      declared variables, objectives, constraints, from a problem file
    formulations/ NLP (CasADi), convex (GP), discrete (catalogue)
    solvers/      solver back-ends behind one Result type
    studies/      solve, Pareto fronts, benchmarks
    cli.py, plots/
"""

__version__ = "0.1.0"
