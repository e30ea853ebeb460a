#!/usr/bin/env python3
"""Pastes the tables under assets/accuracy/ into docs/accuracy.md between marker comments."""
import pathlib, re
root = pathlib.Path(__file__).resolve().parent.parent
readme = root / "docs" / "accuracy.md"
text = readme.read_text()
def table(path):
    lines = (root / path).read_text().splitlines()
    return "\n".join(l for l in lines if l.startswith("|"))
for key, path in [("CORNELL", "assets/accuracy/cornell/summary.md"),
                  ("CAUSTICS", "assets/accuracy/caustics/summary.md"),
                  ("DIAMOND", "assets/accuracy/diamond_bunny/summary.md"),
                  ("PRISM", "assets/accuracy/prism/summary.md"),
                  ("CORNELL_SPECTRAL", "assets/accuracy/cornell_spectral/summary.md"),
                  ("CAUSTICS_ESTIMATORS", "assets/accuracy/caustics_estimators/summary.md"),
                  ("PRISM_ESTIMATORS", "assets/accuracy/prism_estimators/summary.md"),
                  ("DIAMOND_ESTIMATORS", "assets/accuracy/diamond_bunny_estimators/summary.md"),
                  ("COSTS", "assets/accuracy/effect_costs.md")]:
    block = f"<!-- {key} -->\n{table(path)}\n<!-- /{key} -->"
    text = re.sub(rf"<!-- {key} -->.*?<!-- /{key} -->|FIGURES_{key}", lambda _: block, text, flags=re.S)
readme.write_text(text)
