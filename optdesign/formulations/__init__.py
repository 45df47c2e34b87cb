"""Formulations: a design problem turned into something a solver takes.

- :mod:`optdesign.formulations.nlp`: smooth NLP on CasADi (epigraph forms of the min-max
  objectives, scaled variables, exact derivatives); also the naive max/min form.
"""
