"""Formulations: the ways to solve a design problem, one package each, above the
solvers and the global search, below the studies.

- :mod:`optdesign.formulations.nlp`, :mod:`~optdesign.formulations.gp`,
  :mod:`~optdesign.formulations.catalogue`, :mod:`~optdesign.formulations.robust`: each
  owns its solve, diagnosis, sensitivities and typed record, behind one protocol
  (:mod:`optdesign.formulations.protocol`);
- :mod:`optdesign.formulations.registry`: the registered formulations, and the choice
  among them (``formulation="auto"``);
- what they share: the independent check of a design (:mod:`.verify`), the comparison
  with a reference design (:mod:`.reference`), the words of a diagnosis
  (:mod:`.diagnosis`) and the check of a problem with no free variable (:mod:`.fixed`).

The mathematical programs the solvers take (the NLP, the GP) are below the solvers, in
:mod:`optdesign.programs`.
"""
