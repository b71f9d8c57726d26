"""What scripts/check-linuxcnc.sh's job summaries share: a check's JSON result, or a failed
result naming what did not run (a missing or unreadable file)."""
import json


def load(path, what):
    """The JSON result at `path`; when it cannot be read, {"ok": False, "errors": [what]}."""
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {"ok": False, "errors": [what]}
