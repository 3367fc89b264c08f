// Export of any plot: "PNG" (the chart's canvas on a white background,
// with its title), "SVG" (a plain vector drawing of the same series) and
// "CSV" (the plotted series, a header row with names and units). A plot is
// described by a small object, so uPlot charts and hand-drawn canvases
// (the pole-zero map) export alike:
//   { title, canvas(): HTMLCanvasElement, svg(): string, csv(): string }
// uplotExportable(u, title) builds one from a uPlot chart.

import { h } from './forms.js';

/** Save `blob` as `filename` (the browser's download). */
export function download(blob, filename) {
  const a = document.createElement('a');
  const url = URL.createObjectURL(blob);
  a.href = url;
  a.download = filename;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

/** A file name from a title: letters, digits and dashes. */
export function fileStem(title) {
  return (title || 'plot').normalize('NFKD').replace(/[^\w.-]+/g, '-').replace(/^-+|-+$/g, '').slice(0, 80) || 'plot';
}

/** A CSV field, quoted when it needs to be. */
export function csvField(v) {
  if (v == null || (typeof v === 'number' && !Number.isFinite(v))) return '';
  const s = String(v);
  return /[",\n]/.test(s) ? `"${s.replace(/"/g, '""')}"` : s;
}

/** CSV text of columns: `header` names, `cols` equal-length arrays (null → empty). */
export function toCsv(header, cols) {
  const n = Math.max(0, ...cols.map((c) => c.length));
  const lines = [header.map(csvField).join(',')];
  for (let i = 0; i < n; i += 1) lines.push(cols.map((c) => csvField(c[i])).join(','));
  return `${lines.join('\n')}\n`;
}

const esc = (s) => String(s).replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;').replace(/"/g, '&quot;');

/** PNG of a canvas on white, with a title line above it. */
export function pngBlob(canvas, title) {
  const pad = 28;
  const out = document.createElement('canvas');
  out.width = canvas.width;
  out.height = canvas.height + pad;
  const ctx = out.getContext('2d');
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, out.width, out.height);
  ctx.fillStyle = '#1c2430';
  ctx.font = '14px system-ui, sans-serif';
  ctx.fillText(title || '', 8, 19);
  ctx.drawImage(canvas, 0, pad);
  return new Promise((resolve, reject) => out.toBlob((b) => (b ? resolve(b) : reject(new Error('PNG encoding failed'))), 'image/png'));
}

/**
 * The exportable of a uPlot chart: series drawn as SVG polylines (or
 * points/stems) in the chart's own pixel layout, axes with their labels,
 * and a legend; the CSV holds x and every series under their labels.
 */
export function uplotExportable(u, title, { xLabel } = {}) {
  const label = (s, i) => (i === 0 ? (xLabel || u.axes[0].label || s.label || 'x') : s.label);
  return {
    title,
    canvas: () => u.ctx.canvas,
    csv: () => toCsv(u.series.map(label), u.data.map((c) => Array.from(c || []))),
    svg: () => {
      const { width, height } = u;
      const { left, top, width: w, height: ht } = u.bbox;
      const r = uPlotPxRatio(u);
      const [L, T, W, H] = [left / r, top / r, w / r, ht / r];
      const parts = [`<rect x="${L}" y="${T}" width="${W}" height="${H}" fill="none" stroke="#9aa3ad"/>`];
      const xs = u.data[0];
      u.series.forEach((s, i) => {
        if (i === 0 || !s.show) return;
        const color = typeof s._stroke === 'string' ? s._stroke : (typeof s.stroke === 'function' ? s.stroke(u, i) : s.stroke) || '#1f6fb5';
        const scale = s.scale || 'y';
        const ys = u.data[i];
        let d = '';
        let pen = false;
        const dots = [];
        for (let k = 0; k < xs.length; k += 1) {
          const y = ys[k];
          if (y == null || !Number.isFinite(y)) { pen = false; continue; }
          const px = u.valToPos(xs[k], 'x');
          const py = u.valToPos(y, scale);
          if (!Number.isFinite(px) || !Number.isFinite(py)) { pen = false; continue; }
          const X = (L + px).toFixed(1);
          const Y = (T + py).toFixed(1);
          d += `${pen ? 'L' : 'M'}${X} ${Y} `;
          pen = true;
          dots.push([X, Y]);
        }
        if (s.width === 0 || s.paths === null) {
          parts.push(...dots.map(([X, Y]) => `<circle cx="${X}" cy="${Y}" r="2.5" fill="${esc(color)}"/>`));
        } else if (d) {
          parts.push(`<path d="${d.trim()}" fill="none" stroke="${esc(color)}" stroke-width="${s.width || 1}"${s.dash ? ` stroke-dasharray="${s.dash.join(' ')}"` : ''}/>`);
        }
      });
      const legend = u.series.slice(1).filter((s) => s.show).map((s, j) => {
        const color = typeof s.stroke === 'function' ? s.stroke(u, j + 1) : s.stroke;
        return `<text x="${L + 4}" y="${T + 14 + 14 * j}" font-size="11" fill="${esc(color || '#333')}">${esc(s.label)}</text>`;
      });
      const axes = u.axes.map((a, i) => {
        if (!a.label) return '';
        if (i === 0) return `<text x="${L + W / 2}" y="${height - 4}" font-size="11" text-anchor="middle">${esc(a.label)}</text>`;
        const x = a.side === 1 ? width - 6 : 12;
        return `<text transform="translate(${x} ${T + H / 2}) rotate(-90)" font-size="11" text-anchor="middle">${esc(a.label)}</text>`;
      });
      const ticks = u.axes.flatMap((a, i) => {
        const scale = a.scale || (i === 0 ? 'x' : 'y');
        const sc = u.scales[scale];
        if (!sc || sc.min == null) return [];
        return [sc.min, sc.max].map((v, k) => (i === 0
          ? `<text x="${L + (k ? W : 0)}" y="${T + H + 14}" font-size="10" text-anchor="${k ? 'end' : 'start'}">${esc(Number(v.toPrecision(4)))}</text>`
          : `<text x="${L - 4}" y="${T + (k ? 10 : H)}" font-size="10" text-anchor="end">${esc(Number(v.toPrecision(4)))}</text>`));
      });
      return `<svg xmlns="http://www.w3.org/2000/svg" width="${width}" height="${height + 24}" viewBox="0 -24 ${width} ${height + 24}" font-family="system-ui, sans-serif">`
        + `<rect x="0" y="-24" width="${width}" height="${height + 24}" fill="#fff"/>`
        + `<text x="8" y="-8" font-size="13">${esc(title)}</text>${parts.join('')}${legend.join('')}${axes.join('')}${ticks.join('')}</svg>\n`;
    },
  };
}

function uPlotPxRatio(u) {
  return u.ctx.canvas.width / Math.max(1, u.width) || 1;
}

/**
 * The PNG / SVG / CSV buttons of a plot. `get()` returns its exportable
 * (null while there is nothing drawn). `name` becomes the file name.
 */
export function exportBar(get, testid, label = null) {
  const run = async (kind) => {
    const x = get();
    if (!x) return;
    const stem = fileStem(x.title);
    if (kind === 'png') download(await pngBlob(x.canvas(), x.title), `${stem}.png`);
    if (kind === 'svg') download(new Blob([x.svg()], { type: 'image/svg+xml' }), `${stem}.svg`);
    if (kind === 'csv') download(new Blob([x.csv()], { type: 'text/csv' }), `${stem}.csv`);
  };
  return h('span', { class: 'export-bar', 'data-testid': testid || 'export-bar' },
    label ? h('span', { class: 'hint' }, label) : null,
    ['png', 'svg', 'csv'].map((k) => h('button', {
      type: 'button', class: 'btn small', 'data-export': k, title: `Download this plot as ${k.toUpperCase()}${k === 'csv' ? ' (the plotted series, with units)' : ''}`,
      onClick: () => { run(k); },
    }, k.toUpperCase())));
}
