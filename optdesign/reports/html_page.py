"""The page of ``report.html``: HTML, CSS and the script that draws the embedded data
with plotly.js (its basic bundle, inlined packed: the page opens without a network; see
:mod:`optdesign.reports.plotly_js`). A front of three objectives is drawn as its three
projections on the pairs of objectives (the basic bundle draws no 3-D scatter).

Every string of the data is shown as text, whatever it holds: the header is escaped
here (``&``, ``<``, ``>``, ``"`` and ``'``; control characters shown as escapes); the
script builds HTML only through ``esc``, which escapes the same five characters (so a
name is safe in an attribute too); text handed to plotly, which reads a few HTML tags
and ``%{...}`` placeholders in names, titles and hover templates, goes through
``ptext`` (``&``, ``<``, ``>`` and ``%`` as character references, which plotly shows
as the characters).
"""

from __future__ import annotations

import html
import json
from typing import Any

import numpy as np

from optdesign.reports.plotly_js import loader_script
from optdesign.reports.time_response_html import TIME_RESPONSE_SCRIPT, time_response_section
from optdesign.solvers.result import clean_json
from optdesign.text import printable

_CSS = """
body { font-family: system-ui, sans-serif; margin: 1em 2em; color: #222; }
h1 { font-size: 1.3em; margin-bottom: 0.2em; }
.meta { color: #555; margin: 0.2em 0; }
.grid { display: grid; grid-template-columns: minmax(420px, 1fr) minmax(420px, 1fr); gap: 1em; }
.plot { width: 100%; height: 480px; }
#sweep-table { max-height: 420px; overflow: auto; }
table { border-collapse: collapse; font-size: 0.9em; }
td, th { padding: 2px 8px; border-bottom: 1px solid #ddd; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
ul { margin: 0.2em 0 0.8em 0; }
.violated { color: #b00; }
details { margin: 0.5em 0; }
"""

_SCRIPT = r"""
(function () {
  const DATA = JSON.parse(document.getElementById('report-data').textContent);
  const fmt = (v) => (v === null || v === undefined) ? '-' : Number(v).toPrecision(6).replace(/\.?0+(e|$)/, '$1');
  const el = (id) => document.getElementById(id);
  // Text into HTML (element content or a quoted attribute value).
  const ESC = { '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' };
  const esc = (s) => String(s).replace(/[&<>"']/g, (c) => ESC[c]);
  // Text into plotly (trace names, titles, hover templates): shown as written.
  const PTEXT = { '&': '&amp;', '<': '&lt;', '>': '&gt;', '%': '&#37;' };
  const ptext = (s) => String(s).replace(/[&<>%]/g, (c) => PTEXT[c]);
  function list(items, cls) {
    if (!items.length) return '<p class="meta">none</p>';
    return '<ul' + (cls ? ' class="' + cls + '"' : '') + '>' + items.map((t) => '<li>' + esc(t) + '</li>').join('') + '</ul>';
  }
  function table(sel, ref) {
    let h = '<table><tr><th>variable</th><th>what</th><th>' + esc(sel.label) + '</th>';
    if (ref) h += '<th>' + esc(ref.label) + '</th>';
    h += '<th>unit</th><th>bounds</th></tr>';
    sel.design.forEach((row, k) => {
      h += '<tr><td>' + esc(row.name) + '</td><td>' + esc(row.description) + '</td>';
      h += '<td class="num" data-var="' + esc(row.name) + '">' + fmt(row.value) + '</td>';
      if (ref) h += '<td class="num">' + fmt(ref.design[k].value) + '</td>';
      const b = row.lower === undefined ? 'fixed' : '[' + fmt(row.lower) + ', ' + fmt(row.upper) + ']';
      h += '<td>' + esc(row.unit) + '</td><td>' + b + '</td></tr>';
    });
    return h + '</table>';
  }
  function sketchTraces(d, grey) {
    const out = [];
    const n = d.sketch.length;
    d.sketch.forEach((pose, j) => {
      const op = 0.35 + 0.65 * j / Math.max(1, n - 1);
      const name = ptext((grey ? d.label + ', ' : '') + 'phi = ' + pose.phi.toFixed(0) + ' deg');
      pose.links.forEach((link, k) => out.push({
        x: link.map((p) => p[0]), y: link.map((p) => p[1]), mode: 'lines+markers', type: 'scatter',
        line: { width: 3, color: grey ? '#999' : ['#1f77b4', '#ff7f0e', '#2ca02c', '#9467bd'][k % 4], dash: grey ? 'dot' : 'solid' },
        marker: { size: 5 }, opacity: op, name: name, legendgroup: name, showlegend: k === 0,
        hovertemplate: 'x %{x:.1f} mm, y %{y:.1f} mm<extra>' + name + '</extra>' }));
      if (pose.slider) out.push({ x: [pose.slider[0]], y: [pose.slider[1]], type: 'scatter', mode: 'markers',
        marker: { symbol: 'square', size: 10, color: grey ? '#999' : '#2ca02c' }, opacity: op,
        name: 'nut', legendgroup: 'nut' + grey, showlegend: j === 0 && !grey });
      if (j === 0) {
        if (pose.pivots.length) out.push({ x: pose.pivots.map((p) => p[0]), y: pose.pivots.map((p) => p[1]),
          type: 'scatter', mode: 'markers', marker: { symbol: 'triangle-up', size: 11, color: '#000' },
          name: 'ground pivot', showlegend: !grey });
        if (pose.axis) out.push({ x: [pose.axis[0][0], pose.axis[1][0]], y: [pose.axis[0][1], pose.axis[1][1]],
          type: 'scatter', mode: 'lines', line: { color: '#888', width: 1, dash: 'dash' }, name: 'screw axis', showlegend: !grey });
      }
    });
    return out;
  }
  function curveTraces(d, grey) {
    const c = d.curves, out = [];
    const lab = (s) => ptext(s + ' (' + d.label + ')');
    out.push({ x: c.phi, y: c.ratio, type: 'scatter', mode: 'lines', name: lab('ratio'),
      line: { color: grey ? '#999' : '#1f77b4', dash: grey ? 'dot' : 'solid' } });
    if (c.backlash) out.push({ x: c.phi, y: c.backlash, type: 'scatter', mode: 'lines', name: lab('backlash'),
      yaxis: 'y2', line: { color: grey ? '#bbb' : '#d62728', dash: grey ? 'dot' : 'dash' } });
    return out;
  }
  function bandTraces(d) {
    const out = [], phi = d.curves.phi, lo = phi[0], hi = phi[phi.length - 1];
    const b = DATA.bands;
    if (b.mean_ratio) b.mean_ratio.forEach((v, k) => { if (v !== null) out.push({ x: [lo, hi], y: [v, v], type: 'scatter', mode: 'lines',
      line: { color: '#1f77b4', width: 1, dash: 'dashdot' }, name: 'mean ratio ' + (k ? 'max' : 'min') + ' ' + fmt(v) }); });
    if (b.backlash_max !== undefined) out.push({ x: [lo, hi], y: [b.backlash_max, b.backlash_max], yaxis: 'y2', type: 'scatter',
      mode: 'lines', line: { color: '#d62728', width: 1, dash: 'dashdot' }, name: 'backlash max ' + fmt(b.backlash_max) + ' deg' });
    Object.entries(d.active_angles).forEach(([name, angles]) => {
      const ys = angles.map((a) => d.curves.ratio[phi.findIndex((p) => Math.abs(p - a) < 0.051)]);
      out.push({ x: angles, y: ys, type: 'scatter', mode: 'markers', marker: { symbol: 'x', size: 9 },
        name: ptext(name + ' binds') });
    });
    return out;
  }
  const config = { responsive: true, displaylogo: false };
  const COLOURS = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b'];
  const PLOTS = { ok: true };
  function show(i) {
    const d = DATA.designs[i];
    const ref = DATA.reference === null ? null : DATA.designs[DATA.reference];
    el('selected-label').textContent = d.label;
    document.body.dataset.selected = String(i);
    el('design').innerHTML = table(d, ref && ref !== d ? ref : null);
    el('objectives').innerHTML = list(d.objectives.map((o) => o.text).concat(d.facts.map((f) => f.text)));
    el('limits').innerHTML = list(d.limits);
    // a note says what the costs are of, or why they cannot be known (then no list)
    const costs = d.sensitivities || [];
    el('costs').innerHTML = (d.costs_note ? '<p class="meta">' + esc(d.costs_note) + '</p>' : '')
      + (costs.length || !d.costs_note ? list(costs) : '');
    el('steps').innerHTML = (d.item_steps || []).length
      ? '<h3>the neighbouring catalogue items (the rest re-solved)</h3>' + list(d.item_steps) : '';
    el('violated').innerHTML = list(d.violated, 'violated');
    el('reference').innerHTML = ref && ref !== d
      ? '<h3>' + esc(ref.label) + ': violated requirements</h3>' + list(ref.violated, 'violated') : '';
    if (!PLOTS.ok) return;
    let sk = sketchTraces(d, false);
    if (ref && ref !== d) sk = sketchTraces(ref, true).concat(sk);
    if (sk.length) {
      Plotly.react('sketch', sk, { title: { text: 'linkage at the stroke ends and middle' },
        xaxis: { title: { text: 'x (mm)' }, scaleanchor: 'y' }, yaxis: { title: { text: 'y (mm)' } },
        margin: { t: 40 }, legend: { font: { size: 10 }, orientation: 'h', y: -0.25 } }, config);
    } else {
      el('sketch').textContent = 'no sketch for this mechanism';
    }
    let cu = bandTraces(d).concat(curveTraces(d, false));
    if (ref && ref !== d) cu = curveTraces(ref, true).concat(cu);
    Plotly.react('curves', cu, { title: { text: 'ratio and backlash over the stroke' },
      xaxis: { title: { text: 'deflection phi (deg)' } },
      yaxis: { title: { text: 'reduction ratio i (motor rad / output rad)' } },
      yaxis2: { title: { text: 'worst-case backlash (deg)' }, overlaying: 'y', side: 'right', showgrid: false },
      margin: { t: 40 }, legend: { font: { size: 10 }, orientation: 'h', y: -0.25 } }, config);
  }
  function drawFront() {
    // one panel per pair of objectives: two objectives, one panel; three, the three
    // projections (each point in each), side by side
    const f = DATA.front, axes = f.axes.map(ptext), three = axes.length === 3;
    const pairs = three ? [[0, 1], [0, 2], [1, 2]] : [[0, 1]];
    const layout = { title: { text: ptext(f.title || 'Pareto front: hover or click a point') }, hovermode: 'closest', margin: { t: 40 },
      legend: { font: { size: 10 } } };
    const traces = [];
    pairs.forEach(([a, b], k) => {
      const n = k ? String(k + 1) : '', w = 1 / pairs.length;
      layout['xaxis' + n] = { title: { text: axes[a] }, domain: [k * w + (k ? 0.05 : 0), (k + 1) * w - (k < pairs.length - 1 ? 0.05 : 0)], anchor: 'y' + n };
      layout['yaxis' + n] = { title: { text: axes[b] }, anchor: 'x' + n };
      f.traces.forEach((t, j) => {
        const name = ptext(t.method + ' (' + t.index.length + ' points)');
        const trace = { x: t.coords[a], y: t.coords[b], xaxis: 'x' + n, yaxis: 'y' + n, customdata: t.index, type: 'scatter',
          mode: t.mode || (three ? 'markers' : 'markers+lines'), marker: { size: three ? 6 : 8, color: COLOURS[j % COLOURS.length] },
          line: { color: COLOURS[j % COLOURS.length] }, name: name, legendgroup: 'm' + j, showlegend: k === 0 };
        if (three) {
          // the hover names all three objectives, whichever panel the point is in
          trace.text = t.index.map((_, i) => axes.map((ax, m) => ax + ' ' + fmt(t.coords[m][i])).join('<br>'));
          trace.hovertemplate = '%{text}<extra>%{fullData.name}</extra>';
        } else {
          trace.hovertemplate = axes[0] + ' %{x}<br>' + axes[1] + ' %{y}<extra>%{fullData.name}</extra>';
        }
        traces.push(trace);
      });
    });
    return Plotly.newPlot('front', traces, layout, config).then((gd) => {
      const pick = (ev) => { if (ev && ev.points && ev.points.length) show(ev.points[0].customdata); };
      gd.on('plotly_click', pick);
      gd.on('plotly_hover', pick);
    });
  }
  function drawTable() {
    // the sweep's table: a row with a design shows it on hover or click
    const t = DATA.table;
    let h = '<table><tr>' + t.headers.map((x) => '<th>' + esc(x) + '</th>').join('') + '</tr>';
    t.rows.forEach((row, i) => {
      const d = t.design[i];
      h += '<tr' + (d === null ? '' : ' data-design="' + Number(d) + '"') + '>';
      h += row.map((c) => '<td>' + esc(c) + '</td>').join('') + '</tr>';
    });
    el('sweep-table').innerHTML = h + '</table>';
    el('sweep-table').querySelectorAll('tr[data-design]').forEach((tr) => {
      const pick = () => show(Number(tr.dataset.design));
      tr.addEventListener('mouseenter', pick);
      tr.addEventListener('click', pick);
    });
  }
  // The plots wait for plotly.js to be unpacked; a browser that cannot unpack it still
  // shows every table and list, and says why the plots are missing.
  window.plotlyReady.then(() => true, (err) => {
    PLOTS.ok = false;
    ['front', 'sketch', 'curves'].forEach((id) => { if (el(id)) el(id).textContent = 'no plots: ' + err.message; });
    return false;
  }).then((ok) => {
    if (DATA.table) drawTable();
    return ok && DATA.front ? drawFront() : null;
  }).then(() => { if (DATA.selected !== null) show(DATA.selected); document.body.dataset.ready = '1'; });
})();
"""


def render(data: dict[str, Any], title: str) -> str:
    """The whole page for ``data`` (see :mod:`optdesign.reports.html`)."""

    def e(text: object) -> str:  # one line of text, escaped for element content
        return html.escape(printable(text), quote=True)

    reqs = "".join(f"<li>{e(r)}</li>" for r in data["requirements"])
    front = '<div id="front" class="plot"></div>' if data.get("front") else ""
    if data.get("table"):
        front += '<h2>the sweep</h2><div id="sweep-table"></div>'
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>{e(title)}</title>
<style>{_CSS}</style>
<script>{loader_script()}</script>
</head><body>
<h1>{e(data["problem"])} ({e(data["mechanism"])})</h1>
<p class="meta">status {e(data["status"])}; objective {e(data["objective"])}</p>
{"".join(f'<p class="meta">{e(line)}</p>' for line in data.get("claims", []))}
<p class="meta">size, where shown, is the {e(data["size"])}; angles in {e(data["angle_unit"])},
moments in N*m, ripple in %.</p>
<details><summary>requirements (as read from the file)</summary><ul>{reqs}</ul></details>
{front}
<h2>design: <span id="selected-label"></span></h2>
<div class="grid">
<div><div id="design"></div><h3>at this design</h3><div id="objectives"></div></div>
<div><h3>what limits it (binding requirements and bounds)</h3><div id="limits"></div>
<h3>what each limit costs (sensitivity of the optimum)</h3><div id="costs"></div><div id="steps"></div>
<h3>violated requirements</h3><div id="violated"></div><div id="reference"></div></div>
<div id="sketch" class="plot"></div>
<div id="curves" class="plot"></div>
</div>
{time_response_section(data.get("time_response"))}<script type="application/json" id="report-data">{to_json(data)}</script>
<script>{_SCRIPT}{TIME_RESPONSE_SCRIPT if "time_response" in data else ""}</script>
</body></html>
"""


#: Characters written as JSON escapes inside the page's ``<script>`` element: ``<`` and
#: ``>`` (no ``</script>``, ``<!--`` or ``<script`` can appear, in any case), ``&`` (no
#: character reference), U+2028 and U+2029 (line ends to older JavaScript parsers). In
#: JSON they can only occur inside strings, where the escape means the same character.
_IN_SCRIPT = str.maketrans(
    {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "\u2028": "\\u2028", "\u2029": "\\u2029"}
)


def to_json(data: Any) -> str:
    """JSON for embedding in a ``<script type="application/json">`` element.

    Non-finite numbers become ``null`` (``NaN`` is not JSON); ``<``, ``>``, ``&``,
    U+2028 and U+2029 are written as ``\\uXXXX`` escapes, so no text in the data can
    close the element or start a comment in it (a ``<!--`` followed by ``<script`` would
    swallow the rest of the page), and ``JSON.parse`` reads back the same strings."""
    text = json.dumps(clean_json(data), allow_nan=False, default=_default)
    return text.translate(_IN_SCRIPT)


def _default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"not JSON: {type(obj).__name__}")
