"""plotly.js for the pages of ``report.html`` and ``sweep.html``, inlined packed.

The pages draw with plotly.js and must open without a network, so the library travels
inside each page. The full bundle that the ``plotly`` Python package ships is 4.8 MB
(4.8 MB of a 4.84 MB page: the data of a solve is ~16 kB), and the pages need scatter
traces only; so the package ships plotly.js's *basic* bundle (traces ``scatter``,
``bar``, ``pie``; 1.19 MB), gzipped (395 kB), and each page carries it as base64
(527 kB) with a few lines that unpack it in the browser
(``DecompressionStream('gzip')``: Chromium 80, Firefox 113, Safari 16.4) and run it.

The shipped file is ``optdesign/data/plotly-basic.min.js.gz``: ``plotly-basic.min.js``
of the npm package ``plotly.js-basic-dist-min`` at :data:`VERSION` (its sha-256:
:data:`SHA256`), gzipped; plotly.js's MIT licence is beside it
(``plotly-basic.LICENSE.txt``). To move to another release: ``npm pack
plotly.js-basic-dist-min@X``, gzip its ``plotly-basic.min.js`` into that file and update
both constants (``tests/test_reports.py`` checks them against the file).
"""

from __future__ import annotations

import base64
from functools import lru_cache
from pathlib import Path

#: The release of plotly.js's basic bundle that the package ships.
VERSION = "4.1.1"

#: sha-256 of the unpacked ``plotly-basic.min.js`` as the npm package holds it.
SHA256 = "99784e3abfb07b142a15e521a439e6d9addceadb3f79553fd24c72774f0649ba"

#: The shipped file (gzip of the bundle).
BUNDLE = Path(__file__).resolve().parent.parent / "data" / "plotly-basic.min.js.gz"

#: The script that unpacks the bundle: ``window.plotlyReady`` is a promise of
#: ``window.Plotly``, rejected (with the reason) when the browser cannot unpack it; the
#: page then shows its text without plots. The bundle runs by indirect ``eval`` (in the
#: global scope, as a ``<script>`` element would run it) so that the page keeps its three
#: script elements and makes none at run time.
_LOADER = """window.plotlyReady = (async function () {
  if (typeof DecompressionStream === 'undefined') {
    throw new Error('this browser cannot unpack the plotting library (it needs '
      + 'DecompressionStream: Chromium 80, Firefox 113, Safari 16.4 or newer)');
  }
  const packed = '%s';
  const bytes = Uint8Array.from(atob(packed), (c) => c.charCodeAt(0));
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'));
  (0, eval)(await new Response(stream).text());
  return window.Plotly;
})();"""


@lru_cache(maxsize=1)
def packed() -> str:
    """The shipped bundle as base64 (read once per process: every page carries it)."""
    return base64.b64encode(BUNDLE.read_bytes()).decode("ascii")


def loader_script() -> str:
    """The text of the page's first ``<script>`` element: the packed bundle and the code
    that unpacks and runs it (base64 holds no ``<``, ``'`` or ``\\``: nothing in it can
    end the string or the element)."""
    return _LOADER % packed()
