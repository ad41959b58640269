#!/usr/bin/env python3
"""Runs a notebook's code cells in order, as a script, without Jupyter (what CI does with
photon_study.ipynb, at FOTON_EXAMPLES_SMALL=1): plots go to matplotlib's Agg backend.

    FOTON_EXAMPLES_SMALL=1 python examples/run_notebook.py examples/photon_study.ipynb
"""

import json
import sys
import time

import matplotlib

matplotlib.use("Agg")


def main() -> None:
    path = sys.argv[1]
    with open(path, encoding="utf-8") as f:
        cells = json.load(f)["cells"]
    namespace = {"__name__": "__main__"}
    start = time.perf_counter()
    for i, cell in enumerate(cells):
        if cell["cell_type"] != "code":
            continue
        source = "".join(cell["source"])
        exec(compile(source, f"{path}, cell {i + 1}", "exec"), namespace)
    print(f"{path}: ran {sum(c['cell_type'] == 'code' for c in cells)} code cells "
          f"in {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
