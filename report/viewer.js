// The interactive report of a hybridcont study (report.html): the bifurcation diagram in any two of the
// study's columns, coloured by family and drawn by class (stable: thick, physical: solid, not physical:
// dotted and hidden unless asked for), the special points with their labels, the point a click selects with
// its class, stability, phase durations and Floquet multipliers on the unit circle, and the tables of
// families and special points. Everything it shows is in the data block of the page (see study_report.h).
(function () {
  'use strict';
  const study = JSON.parse(document.getElementById('study-data').textContent);
  // Okabe–Ito: distinguishable with any colour vision deficiency.
  const PALETTE = ['#0072B2', '#D55E00', '#009E73', '#CC79A7', '#E69F00', '#56B4E9', '#000000', '#F0E442'];
  const NONPHYSICAL = '#b0b0b0';
  const SYMBOLS = {SB: 'circle', TP: 'circle-open', BP: 'square', PD: 'diamond', NS: 'hexagon', KC: 'star-diamond',
                   GR: 'triangle-down', CB: 'triangle-up', UZ: 'cross', EX: 'x', start: 'star'};

  // Branches by id; special points on a branch the study lists.
  const branchById = new Map(study.branches.map((b) => [b.id, b]));
  const specialPoints = study.special_points.filter((sp) => branchById.has(sp.branch));
  const families = [];
  for (const b of study.branches) if (b.family && !families.includes(b.family)) families.push(b.family);
  const colourOf = (family) => family ? PALETTE[families.indexOf(family) % PALETTE.length] : NONPHYSICAL;
  const fmt = (v, digits = 10) => (typeof v === 'number' && isFinite(v)) ? Number(v.toPrecision(digits)).toString() : '—';

  // Axis choices: every column some branch has, the continued coordinate and the period first.
  const columns = [];
  const add = (name) => { if (!columns.includes(name)) columns.push(name); };
  if (study.branches.length) add(study.branches[0].continued);
  add('T');
  for (const b of study.branches) for (const name of Object.keys(b.columns)) add(name);
  const xSelect = document.getElementById('x-axis'), ySelect = document.getElementById('y-axis');
  for (const select of [xSelect, ySelect]) {
    for (const name of columns) select.add(new Option(name, name));
  }
  xSelect.value = 'T';
  ySelect.value = columns[0];

  document.getElementById('title').textContent = study.model + (study.description ? ': ' + study.description : '');
  document.getElementById('subtitle').textContent =
      study.parameters.map((p) => p.name + ' = ' + fmt(p.value, 6)).join(', ') +
      ' · ' + study.branches.length + ' branches · ' + specialPoints.length + ' special points · ' +
      study.status + ' · hybridcont ' + study.version;

  // One trace per branch and class: the points of other classes are gaps (null), so each line is drawn
  // where its points are of that class.
  function branchTraces(b, x, y, showNonphysical) {
    const traces = [];
    const n = b.columns[x] ? b.columns[x].length : 0;
    if (!n || !b.columns[y]) return traces;
    const kinds = [
      {name: 'stable', test: (i) => b.physical[i] && b.stable[i], width: 4, dash: 'solid'},
      {name: 'physical', test: (i) => b.physical[i], width: 1.6, dash: 'solid'},
      {name: 'not physical', test: (i) => !b.physical[i], width: 1.2, dash: 'dot'},
    ];
    for (const kind of kinds) {
      if (kind.name === 'not physical' && !showNonphysical) continue;
      const xs = [], ys = [], text = [], custom = [];
      let any = false;
      for (let i = 0; i < n; ++i) {
        // A segment belongs to the class when both its ends do (a stable stretch is drawn over the physical one).
        const on = kind.test(i) || (i + 1 < n && kind.test(i + 1) && kind.name === 'not physical');
        xs.push(on ? b.columns[x][i] : null);
        ys.push(on ? b.columns[y][i] : null);
        text.push(describePoint(b, i));
        custom.push([b.id, i]);
        any = any || on;
      }
      if (!any) continue;
      traces.push({
        type: 'scatter', mode: 'lines+markers', x: xs, y: ys, text: text, customdata: custom,
        hovertemplate: '%{text}<extra></extra>', connectgaps: false,
        name: kind.name === 'not physical' ? 'not physical' : (b.family || 'branch ' + b.id),
        meta: kind.name,  // which stretches: 'not physical', 'physical' or 'stable'
        // One legend entry per family (its first physical stretch drawn), the family's stretches grouped under it.
        legendgroup: kind.name === 'not physical' ? 'not physical' : (b.family || 'none'),
        showlegend: legendShown(kind.name === 'not physical' ? 'not physical' : (b.family || 'branch ' + b.id)),
        line: {color: kind.name === 'not physical' ? NONPHYSICAL : colourOf(b.family), width: kind.width, dash: kind.dash},
        marker: {size: 3, color: kind.name === 'not physical' ? NONPHYSICAL : colourOf(b.family)},
      });
    }
    return traces;
  }

  // Whether a legend entry of this name is still to be shown in the drawing being made (draw() resets it).
  let legendNames = new Set();
  function legendShown(name) {
    if (legendNames.has(name)) return false;
    legendNames.add(name);
    return true;
  }

  function describePoint(b, i) {
    const parts = ['branch ' + b.id + ', point ' + i + (b.family ? ' · ' + b.family : '')];
    for (const name of [b.continued, 'T']) if (b.columns[name]) parts.push(name + ' = ' + fmt(b.columns[name][i]));
    parts.push(b.classification[i] + (b.stability[i] ? ', ' + b.stability[i] : ''));
    return parts.join('<br>');
  }

  function specialTrace(x, y, showNonphysical) {
    const xs = [], ys = [], text = [], custom = [], symbols = [], colours = [], labels = [];
    const at = new Map();  // a drawn position -> its index: points that coincide share one label
    for (const sp of specialPoints) {
      const b = branchById.get(sp.branch);
      if (!b || !(x in sp.columns) || !(y in sp.columns)) continue;
      const physical = b.physical[Math.min(sp.index, b.physical.length - 1)] || b.physical[Math.min(sp.index + 1, b.physical.length - 1)];
      if (!physical && !showNonphysical) continue;
      const key = Number(sp.columns[x]).toPrecision(8) + ',' + Number(sp.columns[y]).toPrecision(8);
      if (physical && at.has(key)) {
        labels[at.get(key)] += ' = ' + sp.label;
      } else if (physical) {
        at.set(key, labels.length);
      }
      labels.push(physical && at.get(key) === labels.length ? sp.label : '');
      xs.push(sp.columns[x]);
      ys.push(sp.columns[y]);
      text.push(sp.label + ' on branch ' + sp.branch + (b.family ? ' (' + b.family + ')' : '') + '<br>' +
                b.continued + ' = ' + fmt(sp.coordinate) + ', T = ' + fmt(sp.T) + '<br>' + sp.status +
                (sp.status === 'located' && typeof sp.precision === 'number' ? ' to ' + sp.precision.toExponential(1) : '') +
                (sp.message ? '<br>' + sp.message.slice(0, 160) : ''));
      custom.push([sp.branch, sp.index]);
      symbols.push(SYMBOLS[sp.code] || 'x');
      colours.push(physical ? '#222' : NONPHYSICAL);
    }
    // Each physical point labelled at its marker (up and right of it).
    return {type: 'scatter', mode: 'markers+text', x: xs, y: ys, text: labels, textposition: 'top right',
            textfont: {size: 10, color: '#222'}, hovertext: text, hovertemplate: '%{hovertext}<extra></extra>',
            customdata: custom, showlegend: false,
            marker: {symbol: symbols, size: 9, color: colours, line: {width: 1, color: '#222'}}};
  }

  function draw() {
    const x = xSelect.value, y = ySelect.value, showNonphysical = document.getElementById('show-nonphysical').checked;
    const traces = [];
    legendNames = new Set();
    for (const b of study.branches) traces.push(...branchTraces(b, x, y, showNonphysical));
    traces.push(specialTrace(x, y, showNonphysical));
    const layout = {
      // The families' legend in a row above the plot, left of the toolbar.
      margin: {l: 60, r: 10, t: 40, b: 50}, hovermode: 'closest', dragmode: 'zoom',
      legend: {orientation: 'h', x: 0, xanchor: 'left', y: 1.02, yanchor: 'bottom', font: {size: 11}},
      xaxis: {title: {text: x}, zeroline: false}, yaxis: {title: {text: y}, zeroline: false},
    };
    Plotly.react('diagram', traces, layout, {responsive: true, displaylogo: false, scrollZoom: true});
  }

  // The selected point's orbit, animated as the model draws it: its points at evenly spaced instants of one
  // period, joined by the drawing's lines, its masses as discs of the model's radius, to scale (one scale for
  // both axes, over the whole period), the ground at y = 0.
  let animation = null;
  function animate(b, index) {
    const canvas = document.getElementById('orbit');
    if (animation) cancelAnimationFrame(animation.request);
    animation = null;
    const frames = b.animation && b.animation[index];
    canvas.hidden = !frames || !study.drawing;
    if (canvas.hidden) return;
    const drawing = study.drawing, names = drawing.points;
    const at = (name) => names.indexOf(name);
    const lines = [], masses = [];
    for (const phase of Object.values(drawing.phases || {})) {
      for (const [a, c] of phase.lines || []) lines.push([at(a), at(c)]);
      for (const m of phase.masses || []) masses.push(at(m));
    }
    const r = drawing.mass_radius || 0.05;
    let xmin = Infinity, xmax = -Infinity, ymin = drawing.ground ? 0 : Infinity, ymax = -Infinity;
    for (const f of frames) {
      for (let k = 0; k + 1 < f.length; k += 2) {
        if (f[k] === null || f[k + 1] === null) continue;
        xmin = Math.min(xmin, f[k] - r); xmax = Math.max(xmax, f[k] + r);
        ymin = Math.min(ymin, f[k + 1] - r); ymax = Math.max(ymax, f[k + 1] + r);
      }
    }
    const ctx = canvas.getContext('2d'), W = canvas.width, H = canvas.height, pad = 10;
    const scale = Math.min((W - 2 * pad) / Math.max(xmax - xmin, 1e-9), (H - 2 * pad) / Math.max(ymax - ymin, 1e-9));
    const X = (x) => pad + (x - xmin) * scale + ((W - 2 * pad) - (xmax - xmin) * scale) / 2;
    const Y = (y) => H - pad - (y - ymin) * scale;
    const colour = colourOf(b.family);
    const start = performance.now(), seconds = 2.0;
    const frame = (now) => {
      // requestAnimationFrame's time is the frame's start, which may precede `start`.
      const k = Math.floor((Math.max(0, now - start) / 1000 / seconds) * frames.length) % frames.length;
      const f = frames[k];
      ctx.clearRect(0, 0, W, H);
      if (drawing.ground) {
        ctx.strokeStyle = '#888'; ctx.lineWidth = 1;
        ctx.beginPath(); ctx.moveTo(0, Y(0)); ctx.lineTo(W, Y(0)); ctx.stroke();
      }
      ctx.strokeStyle = '#333'; ctx.lineWidth = 2;
      for (const [a, c] of lines) {
        if (a < 0 || c < 0 || f[2 * a] === null || f[2 * c] === null) continue;  // not placed in this phase
        ctx.beginPath(); ctx.moveTo(X(f[2 * a]), Y(f[2 * a + 1])); ctx.lineTo(X(f[2 * c]), Y(f[2 * c + 1])); ctx.stroke();
      }
      ctx.fillStyle = colour;
      for (const m of masses) {
        if (m < 0 || f[2 * m] === null) continue;
        ctx.beginPath(); ctx.arc(X(f[2 * m]), Y(f[2 * m + 1]), Math.max(r * scale, 2), 0, 2 * Math.PI); ctx.fill();
      }
      animation.request = requestAnimationFrame(frame);
    };
    animation = {request: requestAnimationFrame(frame)};
    canvas.dataset.frames = frames.length;
  }

  // The selected point: its values, class, stability and multipliers. `note`: what the point stands for when it
  // is not the one asked for (a special point lies between two computed points: the one before it is shown).
  function select(branchId, index, note) {
    const b = branchById.get(branchId);
    if (!b) return;
    document.getElementById('hint').hidden = true;
    const rows = [['branch', b.id + (b.family ? ' · ' + b.family : '')], ['point', index],
                  ['class', b.classification[index]], ['stability', b.stability[index] || '—']];
    if (b.word && b.word.length) rows.splice(1, 0, ['word', b.word.join(' > ')]);
    if (note) rows.unshift(['shown', note]);
    // A value below the integration's resolution (|v| < 1e-12, e.g. a state that is zero by symmetry and comes
    // out as 1e-110) is shown as 0.
    const shown = (v) => (typeof v === 'number' && Math.abs(v) < 1e-12 ? '0' : fmt(v));
    for (const name of Object.keys(b.columns)) rows.push([name, shown(b.columns[name][index])]);
    const table = document.createElement('table');
    for (const [k, v] of rows) {
      const tr = table.insertRow();
      tr.insertCell().textContent = k;
      const td = tr.insertCell();
      td.textContent = v;
      td.className = 'number';
    }
    const point = document.getElementById('point');
    point.replaceChildren(table);
    point.dataset.branch = b.id;
    point.dataset.index = index;
    animate(b, index);
    const mu = b.multipliers[index];
    const circle = {type: 'scatter', mode: 'lines', hoverinfo: 'skip', line: {color: '#999', width: 1},
                    x: [...Array(101).keys()].map((k) => Math.cos(2 * Math.PI * k / 100)),
                    y: [...Array(101).keys()].map((k) => Math.sin(2 * Math.PI * k / 100))};
    const traces = [circle];
    if (mu) {
      traces.push({type: 'scatter', mode: 'markers', x: mu.map((m) => m[0]), y: mu.map((m) => m[1]),
                   marker: {size: 9, color: colourOf(b.family)},
                   hovertemplate: 'μ = %{x:.6f} %{y:+.6f}i<extra></extra>'});
    }
    const lim = Math.max(1.3, ...(mu || []).map((m) => Math.hypot(m[0], m[1]) * 1.1));
    Plotly.react('multipliers', traces, {
      // The title left, below the top margin that holds the toolbar (which sits at the top right).
      title: {text: mu ? 'Floquet multipliers' : 'no multipliers (not physical)', font: {size: 12}, x: 0.02,
              xanchor: 'left', y: 0.97, yanchor: 'top'},
      showlegend: false, margin: {l: 30, r: 10, t: 48, b: 30},
      xaxis: {range: [-lim, lim], zeroline: true}, yaxis: {range: [-lim, lim], scaleanchor: 'x', zeroline: true},
    }, {displaylogo: false, responsive: true});
  }

  function fillTable(id, header, rows) {
    const table = document.getElementById(id);
    const head = table.tHead.insertRow();
    for (const h of header) {
      const th = document.createElement('th');
      th.textContent = h;
      head.appendChild(th);
    }
    for (const row of rows) {
      const tr = table.tBodies[0].insertRow();
      for (const cell of row.cells) tr.insertCell().textContent = cell;
      tr.addEventListener('click', () => {
        for (const other of table.querySelectorAll('tr.selected')) other.classList.remove('selected');
        tr.classList.add('selected');
        select(row.branch, row.index, row.note);
      });
    }
  }

  const rangeText = (r) => fmt(Math.min(r.from, r.to)) + ' .. ' + fmt(Math.max(r.from, r.to)) +
                           ' (' + (r.from <= r.to ? r.how_from + ' .. ' + r.how_to : r.how_to + ' .. ' + r.how_from) + ')';
  // An automaton's run crosses several words (phase sequences): each family's word is a column of its own.
  const wordOf = (b) => (b.word || []).join(' > ');
  const severalWords = new Set(study.branches.map(wordOf)).size > 1;
  fillTable('families', ['family', ...(severalWords ? ['word'] : []), 'branch', 'physical', 'stable', 'ends'],
            study.branches.filter((b) => b.ranges.physical.length).map((b) => ({
              branch: b.id, index: b.ranges.physical[0].first_point,
              cells: [b.family || '—', ...(severalWords ? [wordOf(b)] : []),
                      b.id + (b.image_of >= 0 ? ' (image of ' + b.image_of + ')' : ''),
                      b.ranges.physical.map(rangeText).join('; '),
                      b.ranges.stable.length ? b.ranges.stable.map(rangeText).join('; ') : 'nowhere', b.termination],
            })));
  fillTable('special-points', ['label', 'branch', 'family', 'coordinate', 'T', 'status', 'precision'],
            specialPoints.map((sp) => {
              const b = branchById.get(sp.branch);
              const index = Math.min(sp.index, b.physical.length - 1);
              // A start is a computed point; another special point lies between two, of which this is the first.
              const between = sp.code !== 'start' && sp.index + 1 < b.physical.length;
              return {
                branch: sp.branch, index,
                note: between ? 'point ' + index + ', the computed point before ' + sp.label +
                                ' (which lies between points ' + sp.index + ' and ' + (sp.index + 1) + ')' : undefined,
                cells: [sp.label, sp.branch, b.family || '—', b.continued + ' = ' + fmt(sp.coordinate), fmt(sp.T),
                        sp.status, typeof sp.precision === 'number' ? sp.precision.toExponential(1) : '—'],
              };
            }));

  // The parameter plane (a study with curves): where each family continued in H̄ (or a free parameter) is
  // physical (light) and stable (darker), between the curves of the special points that end its ranges or the
  // bound it reached, and every curve, dashed by kind. Regions of mirror images that coincide are drawn once.
  function drawPlane() {
    const plane = study.plane;
    if (!plane) return;
    document.getElementById('plane-panel').hidden = false;
    const coordinate = plane.coordinate || 'H';  // the families' coordinate (H̄ or a free parameter)
    document.getElementById('plane-title').textContent = 'Parameter plane (' + plane.parameter + ', ' + coordinate + ')';
    document.getElementById('plane-note').textContent =
        'Shaded: where a family exists with physical orbits (light) and where they are stable (dark), between ' +
        'the curves of the special points that end its ranges; the dotted line is this run\'s ' + plane.parameter +
        ' = ' + fmt(plane.value, 6) + '.';
    const DASH = {'fold': 'dot', 'branch-point': 'solid', 'period-doubling': 'dash', 'neimark-sacker': 'dashdot',
                  'boundary': 'longdash'};
    const traces = [], drawn = new Map();
    for (const r of plane.regions) {
      const key = r.kind + JSON.stringify(r.polygon);
      if (drawn.has(key)) {  // a mirror image's region: the same set of (p, H)
        const t = drawn.get(key);
        if (!t.name.includes(r.family)) t.name = t.name.replace(' · ', ' = ' + r.family + ' · ');
        continue;
      }
      const t = {type: 'scatter', mode: 'lines', fill: 'toself', x: r.polygon.map((q) => q[0]),
                 y: r.polygon.map((q) => q[1]), name: r.family + ' · ' + r.kind, hoverinfo: 'name',
                 line: {width: 0}, fillcolor: colourOf(r.family), opacity: r.kind === 'stable' ? 0.45 : 0.15};
      drawn.set(key, t);
      traces.push(t);
    }
    for (const c of plane.curves) {
      traces.push({type: 'scatter', mode: 'lines', x: c.points.map((q) => q[0]), y: c.points.map((q) => q[1]),
                   name: c.label + ' · ' + c.type + (c.family ? ' (' + c.family + ')' : ''), hoverinfo: 'name',
                   line: {color: c.family ? colourOf(c.family) : '#444', width: 2, dash: DASH[c.type] || 'solid'}});
    }
    Plotly.react('plane', traces, {
      margin: {l: 60, r: 10, t: 10, b: 50}, hovermode: 'closest', legend: {font: {size: 11}},
      xaxis: {title: {text: plane.parameter}, zeroline: false}, yaxis: {title: {text: coordinate}, zeroline: false},
      shapes: [{type: 'line', xref: 'x', yref: 'paper', x0: plane.value, x1: plane.value, y0: 0, y1: 1,
                line: {color: '#888', width: 1, dash: 'dot'}}],
    }, {responsive: true, displaylogo: false, scrollZoom: true});
  }
  drawPlane();

  for (const el of [xSelect, ySelect, document.getElementById('show-nonphysical')]) el.addEventListener('change', draw);
  draw();
  document.getElementById('diagram').on('plotly_click', (event) => {
    const p = event.points && event.points[0];
    if (p && p.customdata) select(p.customdata[0], p.customdata[1]);
  });
})();
