"""The second hostile corpus (issue 21): cases the first corpus (``tests/hostile_corpus.py``)
does not contain, organised by the issue's eleven classes, and the runner that judges them.

- :mod:`.model`: a case, its expectation, a run's outcome, the verdicts and their counts;
- :mod:`.workspace`: a case's folder (the working directory with sentinel files and
  symbolic links pointing outside, an ``outside`` folder), the snapshot of everything
  outside the output folder, the checks of the output files and of the terminal text;
- :mod:`.verify`: what makes a success a verified result (API objects, ``result.json``);
- :mod:`.server`: a child process that runs CLI and API cases in-process (output captured
  at the file-descriptor level, a memory limit, a time limit) and the parent's client,
  which restarts it after a crash or a hang;
- :mod:`.judge`: one verdict per run;
- :mod:`.cases_files`, :mod:`.cases_api`, :mod:`.cases_more`: the cases;
- :mod:`.special`: signals (class 3) and determinism (class 1), run as real processes;
- :mod:`.fuzz`: the hypothesis fuzz of problem dicts through ``od.load`` / ``od.solve``;
- :mod:`.run`: the corpus as a whole (``python tests/hostile_classes_corpus.py OUT.json``).

A case's expectation follows the issue, not today's behaviour: many cases fail on the
code the corpus was written against (their counts are the issue's "before").
"""
