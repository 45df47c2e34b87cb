"""The second hostile corpus (issue 21): ``python tests/hostile_classes_corpus.py OUT.json``.

Runs every case of ``tests/hostile_classes`` - organised by the issue's eleven classes - through
the command line in the default output mode and with ``--json``, and through the Python
API where it applies, plus the hypothesis fuzz of problem dicts; writes every run's
verdict to OUT.json and prints the counts per class. Options: ``--classes 2,5`` (only
those classes), ``--fast`` (the fast test's subset), ``--match TEXT``, ``--fuzz N`` (draws,
default 200 for the whole corpus, else 0), ``--workdir DIR`` (keep the case folders), ``--quiet``.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parent), str(HERE)]

from hostile_classes.run import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
