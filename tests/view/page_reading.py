"""Reading what a Bokeh page shows, from the browser: its visible text and its documents' data.

Bokeh 3 draws widgets inside shadow roots, so the visible text is collected through them
(style and script elements left out). The data the figures draw is read from the browser's
BokehJS documents, by the names page.py gives its sources and widgets.
"""
from __future__ import annotations

import time

VISIBLE_TEXT_JS = """
function text(node) {
  let out = '';
  if (node.shadowRoot) out += text(node.shadowRoot);
  for (const child of node.childNodes) {
    if (child.nodeType === 3) out += child.textContent + ' ';
    else if (child.nodeType === 1 && !['STYLE', 'SCRIPT'].includes(child.tagName)) out += text(child);
  }
  return out;
}
return text(document.body).replace(/\\s+/g, ' ');
"""

SOURCE_JS = """
const docs = window.Bokeh ? Bokeh.documents : [];
if (!docs.length) return null;
const model = docs[0].get_model_by_name(arguments[0]);
if (!model) return null;
const data = {};
const columns = model.data instanceof Map ? [...model.data.entries()] : Object.entries(model.data);
for (const [key, value] of columns) data[key] = Array.from(value);
return data;
"""

FIND_BUTTON_JS = """
const label = arguments[0];
function find(node) {
  if (node.shadowRoot) { const hit = find(node.shadowRoot); if (hit) return hit; }
  for (const child of node.children || []) {
    if (child.tagName === 'BUTTON' && child.textContent.trim() === label) return child;
    const hit = find(child); if (hit) return hit;
  }
  return null;
}
return find(document.body);
"""


def visible_text(driver) -> str:
    return driver.execute_script(VISIBLE_TEXT_JS)


def source_data(driver, name: str) -> dict | None:
    """The named ColumnDataSource's columns as lists, as the browser holds them."""
    return driver.execute_script(SOURCE_JS, name)


def button(driver, label: str):
    return driver.execute_script(FIND_BUTTON_JS, label)


def wait_for(condition, timeout_s: float, what: str, poll_s: float = 0.5):
    """The first truthy value of ``condition()`` within ``timeout_s``; AssertionError naming ``what``."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout_s:g} s waiting for {what}")
        time.sleep(poll_s)
