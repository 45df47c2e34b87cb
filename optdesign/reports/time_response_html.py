"""The section "Time response" of ``report.html`` for a problem with a ``[loop]``: the
optimum's step response (the fin and the reference, the motor's torque) and its steady
cycle beside the describing function's, from the evaluated
:class:`~optdesign.views.time_response.TimeResponseView` (this module formats it and
computes nothing of the model).

The page gets the section's data under ``time_response``, its HTML from
:func:`time_response_section` and the script that draws it, :data:`TIME_RESPONSE_SCRIPT`,
only when the problem has a ``[loop]``: the page of any other problem is the same, byte
for byte, as without this module.
"""

from __future__ import annotations

import html
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from optdesign.text import printable

if TYPE_CHECKING:
    from optdesign.views.time_response import TimeResponseView


def _plotted(values: Any, scale: float = 1.0) -> list[float | None]:
    """Samples that are only drawn, at 7 significant digits (None: not finite)."""
    return [float(f"{v:.7g}") if math.isfinite(v) else None for v in np.asarray(values) * scale]


def _g(value: float, digits: int = 4) -> str:
    return f"{value:.{digits}g}" if math.isfinite(value) else "-"


def _percent(value: float) -> str:
    return f"{100.0 * value:+.1f} %" if math.isfinite(value) else "-"


def time_response_json(view: TimeResponseView | str) -> dict[str, Any]:
    """What the section shows (JSON-ready): the samples drawn (s, deg, N*m), the lines
    of text and the table of the cycle; or, for a design that could not be simulated,
    why (``error``)."""
    # the view's module is imported here: every page imports this one, and only a solve's
    # report of a problem with [loop] needs it (it brings the loop's models)
    from optdesign.views.time_response import HORIZON_PER_BANDWIDTH, HORIZON_RANGE, SETTLED

    if isinstance(view, str):
        return {"error": view}
    r = view.simulation.response
    deg = 180.0 / math.pi
    angle = f"{view.simulation.angle * deg:+.1f} deg"
    lo, hi = HORIZON_RANGE
    basis = (
        f"{HORIZON_PER_BANDWIDTH:g} / f_b within {lo:g} to {hi:g} s, f_b = "
        f"{view.bandwidth:.4g} Hz the linear loop's bandwidth there"
        if math.isfinite(view.bandwidth)
        else "the longest run the report makes: the linear loop has no bandwidth there"
    )
    lines = [
        f"A {view.step * deg:g} deg step at {angle} of the stroke (the grid angle nearest "
        f"mid-stroke), from rest at the gap's centre, with the chain's gap and damping, "
        f"friction and the motor's limits; {view.horizon:.3g} s simulated ({basis}).",
        f"Over the last third (from {view.tail_start:.3g} s) the fin holds "
        f"{view.settled * deg:.5g} deg on average and "
        + (
            f"comes to rest: it moves +-{view.oscillation * deg:.3g} deg, less than "
            f"{100 * SETTLED:g} % of the gap's half-width b = {view.gap * deg:.3g} deg."
            if view.settles
            else f"moves +-{view.oscillation * deg:.3g} deg ({view.oscillation / view.gap:.3g} "
            f"times the gap's half-width b = {view.gap * deg:.3g} deg)"
            + (
                f" at {view.oscillation_frequency / (2 * math.pi):.4g} Hz."
                if math.isfinite(view.oscillation_frequency)
                else " (fewer than three crossings of its mid-range: no frequency)."
            )
        ),
    ]
    table = None
    cycle = view.cycle
    if cycle is None:
        lines.append(
            "The describing function predicts no stable limit cycle of the clearance at "
            f"this angle: {view.no_cycle}."
        )
    else:
        table = [
            [
                "fin amplitude (deg)",
                _g(cycle.amplitude * deg),
                _g(view.oscillation * deg),
                _percent(view.amplitude_error),
            ],
            [
                "frequency (Hz)",
                _g(cycle.frequency / (2 * math.pi)),
                _g(view.oscillation_frequency / (2 * math.pi)),
                _percent(view.frequency_error),
            ],
        ]
        holds = (
            f"within the {cycle.filter_bound:g} its filter hypothesis asks"
            if cycle.filter_hypothesis_holds
            else f"above the {cycle.filter_bound:g} its filter hypothesis asks: the prediction "
            "is an estimate"
        )
        lines.append(
            "The describing function's stable limit cycle of the clearance at this angle "
            "against the simulated one (half the fin's peak-to-peak over the last third, "
            "and its crossings of the mid-range). The third harmonic's gain "
            f"|L_d(3jw)| / |L_d(jw)| there is {cycle.third_harmonic_gain:.3g}, {holds}."
        )
    return {
        "error": "",
        "lines": lines,
        "table": table,
        "t": _plotted(r.times),
        "reference": _plotted(r.reference, deg),
        "fin": _plotted(r.fin_angle, deg),
        "torque": _plotted(r.motor_torque, 1e-3),
        "close_up": _plotted([view.close_up])[0],
        "cycle": None
        if cycle is None
        else {"t": _plotted(cycle.times), "fin": _plotted(cycle.angle, deg)},
    }


def time_response_section(data: dict[str, Any] | None) -> str:
    """The section's HTML ("" without one): its text and table, escaped, and the two
    plots' elements, which :data:`TIME_RESPONSE_SCRIPT` fills."""
    if data is None:
        return ""

    def e(text: object) -> str:
        return html.escape(printable(text), quote=True)

    out = ['<h2 id="time-response">Time response</h2>']
    if data["error"]:
        return out[0] + f'\n<p class="meta">{e(data["error"])}</p>\n'
    out += [f"<p>{e(line)}</p>" for line in data["lines"]]
    if data["table"]:
        out.append(
            '<table id="cycle-table"><tr><th></th><th>describing function</th>'
            "<th>simulation</th><th>difference</th></tr>"
            + "".join(
                f"<tr><td>{e(row[0])}</td>"
                + "".join(f'<td class="num">{e(c)}</td>' for c in row[1:])
                + "</tr>"
                for row in data["table"]
            )
            + "</table>"
        )
    out.append(
        '<div class="grid"><div id="step-response" class="plot"></div>'
        '<div id="limit-cycle" class="plot"></div></div>'
    )
    return "\n".join(out) + "\n"


#: Draws the section (appended to the page's script only when the page has one). It waits
#: for plotly.js as the page's own drawing does, and marks ``data-time-response`` on the
#: body when done.
TIME_RESPONSE_SCRIPT = r"""
(function () {
  const T = JSON.parse(document.getElementById('report-data').textContent).time_response;
  if (!T || T.error) return;
  const config = { responsive: true, displaylogo: false };
  const legend = { font: { size: 10 }, orientation: 'h', y: -0.2 };
  const done = () => { document.body.dataset.timeResponse = '1'; };
  window.plotlyReady.then(() => {
    Plotly.newPlot('step-response', [
      { x: T.t, y: T.reference, type: 'scatter', mode: 'lines', name: 'reference',
        line: { color: '#000', dash: 'dash', width: 1 } },
      { x: T.t, y: T.fin, type: 'scatter', mode: 'lines', name: 'fin', line: { color: '#1f77b4' } },
      { x: T.t, y: T.torque, type: 'scatter', mode: 'lines', name: 'motor torque', yaxis: 'y2',
        line: { color: '#d62728', width: 1 } }],
      { title: { text: 'step response' }, xaxis: { title: { text: 'time (s)' }, anchor: 'y2' },
        yaxis: { title: { text: 'fin deflection (deg)' }, domain: [0.42, 1] },
        yaxis2: { title: { text: 'motor torque (N*m)' }, domain: [0, 0.3] },
        margin: { t: 40 }, legend: legend }, config);
    const k = T.t.findIndex((t) => t >= T.close_up);
    const tail = [{ x: T.t.slice(k), y: T.fin.slice(k), type: 'scatter', mode: 'lines',
      name: 'fin, simulated', line: { color: '#1f77b4' } }];
    if (T.cycle) tail.push({ x: T.cycle.t, y: T.cycle.fin, type: 'scatter', mode: 'lines',
      name: 'describing function (predicted)', line: { color: '#ff7f0e', dash: 'dot' } });
    Plotly.newPlot('limit-cycle', tail, { title: { text: T.cycle
        ? 'the steady cycle' : 'the end of the run' },
      xaxis: { title: { text: 'time (s)' } }, yaxis: { title: { text: 'fin deflection (deg)' } },
      margin: { t: 40 }, legend: legend }, config);
    done();
  }, (err) => {
    ['step-response', 'limit-cycle'].forEach((id) => {
      document.getElementById(id).textContent = 'no plots: ' + err.message;
    });
    done();
  });
})();
"""
