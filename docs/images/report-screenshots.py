"""The screenshots of docs/tools.md's report section, from a report made by

    foton render scenes/caustics.toml --spp 2048 --seed 99 -o ref.exr --set film.width=160 --set film.height=120
    foton compare scenes/caustics.toml --integrators path,bdpt,vcm,photon --set film.width=160 \
        --set film.height=120 --reference ref.exr --time 2 --curve 3 -o caustics.png --report caustics.html

    PYTHONPATH=python/tests python3 docs/images/report-screenshots.py caustics.html docs/images
"""

import sys
from pathlib import Path

import webdriver

page, out = Path(sys.argv[1]), Path(sys.argv[2])


def pointer(b, x, y):
    b._call("POST", f"/session/{b.session}/actions", {"actions": [{
        "type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"},
        "actions": [{"type": "pointerMove", "duration": 0, "origin": "viewport", "x": x, "y": y}]}]})


def wheel(b, x, y, dy):
    b._call("POST", f"/session/{b.session}/actions", {"actions": [{
        "type": "wheel", "id": "wheel",
        "actions": [{"type": "scroll", "x": x, "y": y, "deltaX": 0, "deltaY": dy, "duration": 0,
                     "origin": "viewport"}]}]})


with webdriver.Browser(1100, 760) as b:
    b.open(page)
    pointer(b, 640, 470)
    for _ in range(4):
        wheel(b, 640, 470, -100)
    pointer(b, 642, 472)
    b.screenshot(out / "report-zoom.png")
    b.key("f4mm")
    b.screenshot(out / "report-rel.png")
    b.key("mmm")
    b.screenshot(out / "report-flip.png")
    b.script('document.getElementById("curves-section").scrollIntoView()')
    b.screenshot(out / "report-numbers.png")
    assert not b.log()
