// Small DOM helpers for the side panel.

export function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (k === 'text') e.textContent = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

export function formatValue(v) {
  if (v === null || v === undefined) return '–';
  if (typeof v === 'boolean') return v ? 'yes' : 'no';
  if (typeof v === 'number') {
    if (Number.isInteger(v)) return v.toLocaleString('en-US');
    const a = Math.abs(v);
    return a !== 0 && (a < 1e-3 || a >= 1e5) ? v.toExponential(3) : v.toPrecision(4);
  }
  return String(v);
}

// A two-column table of [label, value] rows; returns the element.
export function table(rows) {
  const t = el('table');
  for (const [k, v] of rows) t.append(el('tr', {}, el('td', { text: k }), el('td', { text: formatValue(v) })));
  return t;
}

export function legend(items) {
  const d = el('div', { class: 'legend' });
  for (const [colour, label] of items) {
    const swatch = el('span');
    swatch.style.background = colour;
    d.append(swatch, label);
  }
  return d;
}

export function rgbCss([r, g, b]) {
  return `rgb(${Math.round(r * 255)}, ${Math.round(g * 255)}, ${Math.round(b * 255)})`;
}
