"""The comparison's table: its columns and how their values print, as Markdown or HTML."""
import html
from typing import Dict, List, Sequence

import numpy as np

Row = Dict[str, object]  # one method's measures by column key

# Column key -> heading, in table order. A row lacks the keys its comparison did not measure
# (the truth-based ones without a ground truth).
COLUMNS = {
    "method": "method",
    "seconds": "seconds",
    "faces": "faces",
    "loops": "boundary loops",
    "loop_sizes": "loop sizes (edges, largest first)",
    "unsupported_pct": "unsupported area % (>2 spacings from every sample)",
    "loops_found": "true boundaries found",
    "chamfer_pct": "chamfer (% diag)",
    "spurious_pct": "spurious area %",
    "missing_pct": "missing area %",
    "boundary_distance_pct": "boundary distance (% diag)",
}


def format_value(value) -> str:
    """A cell: floats to 3 significant digits (nan: 'n/a'), lists cut after 8 items, None empty."""
    if value is None:
        return ""
    if isinstance(value, float):
        return "n/a" if np.isnan(value) else f"{value:.3g}"
    if isinstance(value, list):
        shown = ", ".join(str(v) for v in value[:8])
        return shown + (f", … ({len(value)} in all)" if len(value) > 8 else "") if value else "none"
    return str(value)


def columns(rows: Sequence[Row]) -> List[str]:
    """The keys of :data:`COLUMNS` that some row has, in table order."""
    return [k for k in COLUMNS if any(k in row for row in rows)]


def markdown(rows: Sequence[Row]) -> str:
    """The rows as a Markdown table."""
    keys = columns(rows)
    lines = ["| " + " | ".join(COLUMNS[k] for k in keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(format_value(row.get(k)) for k in keys) + " |" for row in rows]
    return "\n".join(lines)


def html_table(rows: Sequence[Row]) -> str:
    """The rows as an HTML <table>."""
    keys = columns(rows)
    head = "".join(f"<th>{html.escape(COLUMNS[k])}</th>" for k in keys)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(format_value(row.get(k)))}</td>" for k in keys) + "</tr>"
                   for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"
