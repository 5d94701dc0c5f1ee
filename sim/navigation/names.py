"""The navigation policies' ``--navigator`` names and what each does, for the command line's help.

Light on purpose (no numpy, no simulator), so that ``abstract-map --help`` stays
fast; :data:`sim.navigation.policies.NAVIGATORS` maps the same names, in the
same order, to the policy classes (tested).
"""

from __future__ import annotations

DEFAULT_NAVIGATOR = "guided"  # the best by the generalisation benchmark (benchmarks/run.py generalise), and within
# the check on the zoo with the camera; ``paper`` is the paper's robot

NAVIGATOR_SUMMARIES: dict[str, str] = {
    "paper": "the paper's robot: to the goal's imagined position, growing the model when the goal is not there",
    "frontier": "the nearest frontier; reads no sign: the no-signs lower bound",
    "viewpoint": "negative information: to where the goal's label may still be read",
    "guided": "the frontier with the best rate of goal belief per metre walked past it, from the arrows, signs, "
              "doorways and abstract map; it reads the plates it sees from afar",
    "even-prior": "guided without the abstract map's imagined goal (the goal's prior even over the map): an "
                  "ablation, what the model's point is worth in a building",
    "known-goal": "guided told where the goal's label hangs: an informed reference, not a navigator for unseen "
                  "buildings",
    "known-pose": "told where the goal's label hangs and which way it faces, straight there over the map as it "
                  "grows: the informed point-goal reference, not a navigator for unseen buildings",
}


def navigator_help(default: str | None = None) -> str:
    """Every navigator as ``name (what it does)``, ``default`` marked as such."""
    return "; ".join(f"{name} ({summary}{'; default' if name == default else ''})"
                     for name, summary in NAVIGATOR_SUMMARIES.items())
