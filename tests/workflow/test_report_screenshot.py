"""`snakemake --report report.html` after the smoke study: self-contained, every figure the rules
declare with report() embedded byte for byte with its caption, and each figure shown by the report
itself in headless Chromium (Debian `chromium`), offline, checked pixel by pixel in a screenshot."""
import base64
import json
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageFilter  # Pillow: a dependency of matplotlib

from test_snakemake import REPO, _run, _study

CHROMIUM = Path("/usr/bin/chromium")
MATERIAL = "linear_polymer"
SMOKE = ["--configfile", "config/studies/smoke.yaml"]
WINDOW = (1400, 1000)
# The module's tests share one smoke study and its report (a module fixture): one xdist worker.
pytestmark = pytest.mark.xdist_group("report")

# The report is a React app that opens on the rule graph and shows one result at a time, with no
# URL to a result. This script, appended to a copy of the report, navigates as a reader does:
# clicks the category, the subcategory (skipped by the report when there is only one), then the
# result's view button, and logs the shown <img>'s natural size to the console.
NAVIGATE = """
(function () {
  const want = JSON.parse(document.getElementById("suspsim-target").textContent);
  function link(text) {
    const a = [...document.querySelectorAll("a")].find((a) => a.textContent.trim() === text);
    if (a) a.click();
    return Boolean(a);
  }
  const steps = [
    () => link(want.category),
    () => (document.querySelector("tr") !== null || link(want.subcategory)),
    () => {
      const row = [...document.querySelectorAll("tr")]
        .find((tr) => tr.cells.length && tr.cells[0].textContent.trim() === want.path);
      if (row) row.querySelector("a").click();
      return Boolean(row);
    },
    () => {
      const img = [...document.images]
        .find((i) => i.getAttribute("src") === results[want.path].data_uri);
      if (!img || !img.complete || !img.naturalWidth) return false;
      console.log("suspsim-view shown " + want.path + " " + img.naturalWidth + "x" + img.naturalHeight);
      return true;
    },
  ];
  let step = 0, tries = 0;
  (function next() {
    if (step === steps.length) return;
    if (steps[step]()) { step += 1; tries = 0; }
    else if (++tries > 200) { console.error("suspsim-view failed at step " + step); return; }
    setTimeout(next, 20);
  })();
})();
"""


def _declared_figures():
    """{file name: (category, caption file)} of every report() output in workflow/rules/."""
    text = "".join(p.read_text() for p in sorted((REPO / "workflow/rules").glob("*.smk")))
    found = {}
    for m in re.finditer(r'report\(\s*f"\{RESULTS\}/\{\{material\}\}/([^"]+)",([^)]*)\)', text):
        args = dict(re.findall(r'(\w+)="([^"]*)"', m[2]))
        found[m[1]] = (args["category"], args["caption"])
    return found


FIGURES = _declared_figures()


def _script_json(html, name):
    match = re.search(rf'<script id="{name}">\s*var \w+ = (.*?);\s*</script>', html, re.DOTALL)
    assert match, f"report.html has no <script id={name!r}> data block"
    return json.loads(match[1])


@pytest.fixture(scope="session")
def report(tmp_path_factory):
    """The smoke study run in a copy of the workflow, then its report: (study folder, report)."""
    study = _study(tmp_path_factory.mktemp("report") / "study",
                   {MATERIAL: REPO / f"data/{MATERIAL}/matrix.csv"})
    proc = _run(study, *SMOKE, cores="2")
    assert proc.returncode == 0, proc.stderr
    proc = _run(study, *SMOKE, "--report", "report.html")
    assert proc.returncode == 0, proc.stderr
    return study, study / "report.html"


#: Rule files of the studies that are not the material pipeline (their figures are not in the
#: smoke study's report, and their own workflow tests run them).
OTHER_STUDIES = {"speed_error", "dst", "flows", "bingham_suspension"}


def test_every_report_output_of_the_rules_is_parsed():
    """Every report() of the material pipeline's rule files is in FIGURES, so the smoke
    study's report is checked for it; the other studies' rule files hold the rest."""
    calls = {p.stem: p.read_text().count("report(")
             for p in (REPO / "workflow/rules").glob("*.smk")}
    material = sum(n for stem, n in calls.items() if stem not in OTHER_STUDIES)
    assert len(FIGURES) == material > 0
    assert all(calls.get(stem, 0) > 0 for stem in OTHER_STUDIES)
    assert all(caption.endswith(".rst") for _, caption in FIGURES.values())


@pytest.mark.slow
def test_report_is_self_contained_and_embeds_every_declared_figure_with_its_caption(report):
    study, html_path = report
    html = html_path.read_text(encoding="utf-8")
    # Nothing is fetched: no script, stylesheet, image or frame from another host.
    assert not re.findall(r'<(?:script|link|img|iframe)\b[^>]*\b(?:src|href)\s*=\s*["\']?'
                          r'(?:https?:)?//', html, re.IGNORECASE)
    results = _script_json(html, "results")
    expected = {f"results/{MATERIAL}/{name}": figure for name, figure in FIGURES.items()}
    assert set(results) == set(expected)
    categories = {}
    for path, (category, _) in expected.items():
        categories.setdefault(category, {}).setdefault(MATERIAL, []).append(path)
    assert {c: {s: sorted(p) for s, p in subs.items()}
            for c, subs in _script_json(html, "categories").items()} == \
        {c: {s: sorted(p) for s, p in subs.items()} for c, subs in categories.items()}
    for path, (_, caption_file) in expected.items():
        entry = results[path]
        assert entry["mime_type"] == "image/png"
        header, _, data = entry["data_uri"].partition(";base64,")
        assert header.startswith("data:image/png")
        assert base64.b64decode(data) == (study / path).read_bytes(), path
        # The caption is rendered: the template's opening words, the wildcard filled in.
        template = (REPO / "workflow/rules" / caption_file).resolve().read_text(encoding="utf-8")
        opening = " ".join(template.split("{{")[0].split())
        caption = " ".join(re.sub(r"<[^>]+>", " ", entry["caption"]).split())
        assert caption.startswith(opening), (path, caption[:120])
        assert f"of {MATERIAL}" in caption and "{{" not in caption and "}}" not in caption


def _screenshot(report_html, target, out_dir):
    """A copy of the report that navigates to target, screenshot in headless Chromium offline.

    Returns the PNG path and Chromium's console messages.
    """
    html = report_html.read_text(encoding="utf-8")
    at = html.rindex("</body>")
    view = out_dir / "view.html"
    view.write_text(html[:at] + '<script id="suspsim-target" type="application/json">'
                    f"{json.dumps(target)}</script>\n<script>{NAVIGATE}</script>\n" + html[at:],
                    encoding="utf-8")
    png = out_dir / "screenshot.png"
    profile = out_dir / "chromium-profile"
    profile.mkdir()
    proc = subprocess.run(
        [str(CHROMIUM), "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
         "--no-first-run", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", "--disable-dev-shm-usage",
         # Offline: every host name fails to resolve, so the report must bring everything.
         "--host-resolver-rules=MAP * ~NOTFOUND",
         "--enable-logging=stderr", "--v=0",  # console messages to stderr
         f"--user-data-dir={profile}", f"--window-size={WINDOW[0]},{WINDOW[1]}",
         "--virtual-time-budget=10000", f"--screenshot={png}", view.as_uri()],
        capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-3000:]
    console = re.findall(r':CONSOLE[^\]]*\] "(.*)", source:', proc.stderr)
    return png, console


def _bbox(mask):
    ys, xs = np.nonzero(mask)
    return xs.min(), ys.min(), xs.max() + 1, ys.max() + 1


def _match(shot, figure):
    """How the screenshot's content area (right of the navigation bar) shows the figure.

    The drawn (non-white) part of each is cropped and the figure's scaled onto the screen's:
    aspect is the ratio of the two scale factors (1: neither distorted nor cut off), width the
    shown width as a fraction of the content area, correlation that of the two grey images.
    """
    rgb = np.asarray(shot.convert("RGB"))
    row = rgb[rgb.shape[0] // 2].astype(int)
    x0 = int(np.argmax(np.any(row != row[0], axis=1)))  # the bar is one colour at mid-height
    assert 0 < x0 < rgb.shape[1] // 2, f"no navigation bar found (content from x = {x0})"
    left, top, right, bottom = _bbox(np.any(rgb[:, x0:] < 250, axis=2))
    left, right = left + x0, right + x0
    white = Image.new("RGBA", figure.size, "white")
    drawn = Image.alpha_composite(white, figure.convert("RGBA")).convert("L")
    box = _bbox(np.asarray(drawn) < 250)
    sx, sy = (right - left) / (box[2] - box[0]), (bottom - top) / (box[3] - box[1])
    expected = drawn.crop(box).resize((right - left, bottom - top), Image.LANCZOS)
    shown = shot.convert("L").crop((left, top, right, bottom))
    blur = ImageFilter.GaussianBlur(1)  # resampling moves thin lines by a pixel
    a = np.asarray(expected.filter(blur), dtype=float).ravel()
    b = np.asarray(shown.filter(blur), dtype=float).ravel()
    return {"aspect": round(float(sx / sy), 4),
            "width": round(float((right - left) / (rgb.shape[1] - x0)), 3),
            "correlation": round(float(np.corrcoef(a, b)[0, 1]), 3)}


@pytest.mark.slow
@pytest.mark.skipif(not CHROMIUM.exists(),
                    reason=f"{CHROMIUM} not installed: apt-get install chromium (Debian)")
@pytest.mark.parametrize("name", sorted(FIGURES))
def test_headless_chromium_shows_the_figure_in_the_report(report, name, tmp_path):
    study, html_path = report
    path = f"results/{MATERIAL}/{name}"
    category = FIGURES[name][0]
    png, console = _screenshot(html_path, {"category": category, "subcategory": MATERIAL,
                                           "path": path}, tmp_path)
    figure = Image.open(study / path)
    assert not [m for m in console if m.startswith("Uncaught") or "suspsim-view failed" in m], \
        console
    assert f"suspsim-view shown {path} {figure.width}x{figure.height}" in console, console

    shot = Image.open(png)
    assert shot.format == "PNG" and shot.size == WINDOW
    rgb = np.asarray(shot.convert("RGB"))
    colours = np.unique(rgb.astype(np.int32) @ np.array([1 << 16, 1 << 8, 1], dtype=np.int32))
    assert colours.size > 500 and rgb.std() > 20, "blank page"

    match = _match(shot, figure)
    assert abs(match["aspect"] - 1) < 0.02, f"{png}: figure shown distorted or cut off ({match})"
    assert match["width"] > 0.5, f"{png}: figure shown too small to read ({match})"
    assert match["correlation"] > 0.8, f"{png} does not show {path} ({match})"
