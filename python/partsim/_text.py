"""Small text formats shared by partsim's Python commands."""

import math


def duration(s):
    """Seconds as '1h02m', '3m05s' or '12s' ('?' when not finite): an ETA in progress lines."""
    if not math.isfinite(s):
        return "?"
    s = int(round(s))
    if s >= 3600:
        return f"{s // 3600}h{s % 3600 // 60:02d}m"
    if s >= 60:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s}s"
