// The report of a hybridcont sweep (sweep-report.html): per family, the grid coloured by where the family
// exists, is physical and is stable (or by the ends of its ranges), a click on a grid point shows its row of
// the table; with curves (a sweep with curves = p), the (p, H) plane along the grid line through the selected
// point. Everything it shows is in the data block of the page (python/hybridcont/sweeps.py, write_report).
(function () {
  'use strict';
  const data = JSON.parse(document.getElementById('sweep-data').textContent);
  const PALETTE = ['#0072B2', '#D55E00', '#009E73', '#CC79A7', '#56B4E9', '#E69F00', '#000000'];
  const CLASSES = data.classes;  // from "study failed" to "stable"
  const names = Object.keys(data.grid);
  const fmt = (v) => (typeof v === 'number' && isFinite(v)) ? Number(v.toPrecision(10)).toString() : '—';
  document.getElementById('title').textContent = data.model + ': ' + names.join(' × ') + ' (' + data.points.length + ' grid points)';
  document.getElementById('subtitle').textContent = 'strategy ' + data.strategy + ' · hybridcont ' + data.version;
  const familySelect = document.getElementById('family'), colourSelect = document.getElementById('colour');
  data.families.forEach((f) => familySelect.add(new Option(f, f)));

  function shades(family) {
    const c = PALETTE[data.families.indexOf(family) % PALETTE.length];
    return ['#f2c4c4', '#f3edc9', '#ffffff', '#d9d9d9', c + '55', c];
  }
  const xy = (p) => [p.values[names[0]], names.length > 1 ? p.values[names[1]] : 0];
  // Square markers the size of a grid cell, whatever the plot's size.
  function markerSize() {
    const el = document.getElementById('map');
    const nx = data.grid[names[0]].length, ny = names.length > 1 ? data.grid[names[1]].length : 1;
    return Math.max(4, Math.min((el.clientWidth - 160) / nx, (el.clientHeight - 120) / ny));  // cells that touch
  }
  // "physical 1.2 .. 1.4, 1.6 .. 1.9": every disjoint interval of the table's "a..b;c..d".
  function ranges(kind, text) {
    if (!text) return '';
    return '<br>' + kind + ' ' + text.split(';').map((r) => r.split('..').map((v) => fmt(Number(v))).join(' .. ')).join(', ');
  }
  function describe(p, family) {
    const f = p.families[family] || {};
    return names.map((n) => n + ' = ' + fmt(p.values[n])).join(', ') + '<br>' + family + ': ' + CLASSES[f.class] +
           ranges('physical', f.physical_ranges) + ranges('stable', f.stable_ranges) +
           '<br>' + p.status + ' · ' + p.strategy;
  }
  function draw() {
    const family = familySelect.value, colour = colourSelect.value, size = markerSize();
    const traces = [];
    if (colour === 'class') {
      const s = shades(family);
      CLASSES.forEach((name, k) => {
        const pts = data.points.filter((p) => (p.families[family] || {}).class === k);
        if (!pts.length) return;
        traces.push({type: 'scatter', mode: 'markers', name: name, x: pts.map((p) => xy(p)[0]), y: pts.map((p) => xy(p)[1]),
                     text: pts.map((p) => describe(p, family)), customdata: pts.map((p) => p.id), hovertemplate: '%{text}<extra></extra>',
                     marker: {symbol: 'square', size: size, color: s[k], line: {width: 0.5, color: '#999'}}});
      });
    } else {
      const pts = data.points.filter((p) => typeof (p.families[family] || {})[colour] === 'number');
      traces.push({type: 'scatter', mode: 'markers', name: colour.replace('_', ' '), x: pts.map((p) => xy(p)[0]),
                   y: pts.map((p) => xy(p)[1]), text: pts.map((p) => describe(p, family)), customdata: pts.map((p) => p.id),
                   hovertemplate: '%{text}<extra></extra>',
                   marker: {symbol: 'square', size: size, color: pts.map((p) => p.families[family][colour]), colorscale: 'Viridis',
                            showscale: true, colorbar: {title: {text: colour.replace('_', ' ')}}}});
    }
    Plotly.react('map', traces, {
      // The legend in a row above the plot, left of the toolbar (top right): never under it.
      margin: {l: 60, r: 10, t: 40, b: 50}, hovermode: 'closest',
      legend: {font: {size: 11}, orientation: 'h', x: 0, xanchor: 'left', y: 1.02, yanchor: 'bottom'},
      showlegend: colour === 'class',  // the classes present, even when only one is
      xaxis: {title: {text: names[0]}, zeroline: false},
      yaxis: names.length > 1 ? {title: {text: names[1]}, zeroline: false} : {visible: false},
    }, {responsive: true, displaylogo: false});
  }
  // The (p, H) plane along the grid line through a grid point (a sweep with curves = p): the selected
  // family's ranges at each grid point of the line — physical thin and light, stable thick — and the
  // two-parameter curves of the line's curve point over them.
  const curves = data.curves || null;
  const CURVE_DASH = {'period-doubling': 'dash', 'neimark-sacker': 'dashdot', 'branch-point': 'dot', 'fold': 'longdash',
                      'boundary': 'solid'};
  let lineOf = null;
  function drawPlane() {
    if (!curves || lineOf === null) return;
    const family = familySelect.value, axis = names.indexOf(curves.parameter);
    const key = lineOf.split('_').map((v, i) => (i === axis ? '*' : v)).join('_');
    const line = curves.lines[key];
    const onLine = data.points.filter((p) => p.id.split('_').map((v, i) => (i === axis ? '*' : v)).join('_') === key);
    const colour = shades(family)[5], traces = [];
    for (const [kind, width, opacity] of [['physical', 3, 0.35], ['stable', 9, 1]]) {
      const x = [], y = [];
      for (const p of onLine) {
        const f = p.families[family] || {}, a = f[kind + '_from'], b = f[kind + '_to'];
        if (typeof a !== 'number' || typeof b !== 'number') continue;
        x.push(p.values[curves.parameter], p.values[curves.parameter], null);
        y.push(a, b, null);
      }
      traces.push({type: 'scatter', mode: 'lines', name: family + ': ' + kind + ' range', x: x, y: y, opacity: opacity,
                   line: {color: colour, width: width}, hoverinfo: 'skip'});
    }
    for (const c of (line ? line.curves : [])) {
      traces.push({type: 'scatter', mode: 'lines', name: c.type + ' curve of ' + c.label + (c.family ? ' (' + c.family + ')' : ''),
                   x: c.p, y: c.H, line: {color: c.family === family ? '#222' : '#999', width: 1.5, dash: CURVE_DASH[c.type] || 'solid'},
                   hovertemplate: c.label + ': ' + curves.parameter + ' = %{x}, H = %{y}<extra></extra>'});
    }
    const others = names.filter((n) => n !== curves.parameter).map((n) => n + ' = ' + fmt(onLine.length ? onLine[0].values[n] : NaN));
    document.getElementById('plane-title').textContent = family + ' in (' + curves.parameter + ', H)' +
        (others.length ? ' along ' + others.join(', ') : '') + (line ? ': curves continued from grid point ' + line.point : ': no curves on this line');
    Plotly.react('plane', traces, {
      margin: {l: 60, r: 10, t: 10, b: 50}, hovermode: 'closest', legend: {font: {size: 11}},
      xaxis: {title: {text: 'parameter ' + curves.parameter}, zeroline: false},
      yaxis: {title: {text: 'energy H'}, zeroline: false},
    }, {responsive: true, displaylogo: false});
  }
  function select(id) {
    const p = data.points.find((q) => q.id === id);
    if (!p) return;
    if (curves) {
      lineOf = id;
      drawPlane();
    }
    const table = document.createElement('table');
    const rows = [['grid point', p.id], ...names.map((n) => [n, fmt(p.values[n])]), ['status', p.status], ['strategy', p.strategy]];
    for (const [family, f] of Object.entries(p.families)) {
      rows.push([family, CLASSES[f.class] + (f.special_points ? ' · ' + f.special_points : '')]);
    }
    for (const [k, v] of rows) {
      const tr = table.insertRow();
      tr.insertCell().textContent = k;
      tr.insertCell().textContent = v;
    }
    document.getElementById('point').replaceChildren(table);
  }
  familySelect.addEventListener('change', () => { draw(); drawPlane(); });
  colourSelect.addEventListener('change', draw);
  window.addEventListener('resize', draw);
  draw();
  if (curves) {  // the line through the first curve point, until a click selects another
    const first = Object.values(curves.lines)[0];
    lineOf = first ? first.point : (data.points[0] || {}).id || null;
    drawPlane();
  }
  document.getElementById('map').on('plotly_click', (e) => { if (e.points && e.points[0]) select(e.points[0].customdata); });
})();
