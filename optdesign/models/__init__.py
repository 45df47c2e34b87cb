"""Physics models: pure functions written once, evaluated symbolically or numerically.

Each function accepts floats, NumPy arrays (broadcast) or CasADi symbols and returns the
same kind, through :mod:`optdesign.math`. Units: mm, N, MPa, N*mm, rad.
"""
