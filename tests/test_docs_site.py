"""The documentation site builds without a warning and its pages render in a browser."""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
MATERIAL_INDIGO = (63, 81, 181)  # the header's colour (mkdocs.yml: primary indigo)


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``mkdocs build --strict`` into a temporary folder, as CI runs it."""
    for module in ("mkdocs", "material", "mkdocstrings_handlers.python"):
        if importlib.util.find_spec(module.split(".")[0]) is None:
            pytest.skip(f"{module} is not installed: pip install -e '.[docs]'")
    out = tmp_path_factory.mktemp("site")
    built = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(ROOT / "mkdocs.yml"),
         "-d", str(out)], cwd=ROOT, capture_output=True, text=True, timeout=300,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert built.returncode == 0, built.stderr
    assert "WARNING" not in built.stderr, built.stderr
    return out


@pytest.fixture(scope="module")
def browser() -> str:
    found = next((path for name in BROWSERS if (path := shutil.which(name))), None)
    if found is None:
        pytest.skip(f"no headless browser ({', '.join(BROWSERS)}) on the PATH")
    return found


def chromium(browser: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
         "--window-size=1280,1600", "--virtual-time-budget=3000", *args],
        capture_output=True, text=True, timeout=120)


def render(browser: str, page: Path, shot: Path) -> str:
    """The page's DOM after its scripts ran, and a screenshot of it at 1280 x 1600."""
    dom = chromium(browser, "--dump-dom", page.as_uri())
    assert dom.returncode == 0, dom.stderr
    taken = chromium(browser, f"--screenshot={shot}", page.as_uri())
    assert taken.returncode == 0 and shot.is_file(), taken.stderr
    return dom.stdout


def looks_rendered(shot: Path) -> None:
    """Not a blank page: many colours, and the Material theme's indigo header on top."""
    from PIL import Image

    with Image.open(shot) as image:
        rgb = image.convert("RGB")
        assert rgb.size == (1280, 1600)
        colours = rgb.getcolors(maxcolors=1 << 20) or []
        assert len(colours) > 50, f"{shot}: {len(colours)} colours, a blank page?"
        top = rgb.getpixel((640, 10))
        assert all(abs(a - b) <= 8 for a, b in zip(top, MATERIAL_INDIGO, strict=True)), (
            f"{shot}: {top} on top, not the Material theme's indigo header")


def test_the_site_builds_strict_with_every_page(site: Path) -> None:
    """Every page of the nav is built, the generated references and the API pages among them."""
    for page in ("index.html", "getting-started.html", "missions.html", "world.html",
                 "events.html", "reference/cli.html", "reference/python/index.html",
                 "howto/strategy.html", "concepts/assignment.html", "changelog.html"):
        assert (site / page).is_file(), page
    cli = (site / "reference" / "cli.html").read_text(encoding="utf-8")
    assert "astralis world import" in cli and "--keep-strays" in cli  # the parser's help


def test_the_home_page_renders(site: Path, browser: str, tmp_path: Path) -> None:
    """The home page in Chromium: its title, a heading, the nav, the replay picture."""
    dom = render(browser, site / "index.html", tmp_path / "home.png")
    assert "<title>astralis-des</title>" in dom
    assert 'id="where-to-go"' in dom
    assert "Getting started" in dom and "replay_urban_search.png" in dom
    looks_rendered(tmp_path / "home.png")


def test_the_mission_reference_renders(site: Path, browser: str, tmp_path: Path) -> None:
    """The mission reference in Chromium: a key's row with its default and example, and the
    strategies with the options they read."""
    dom = render(browser, site / "missions.html", tmp_path / "missions.png")
    assert "<h1 id=\"mission-file-reference\">Mission file reference" in dom
    assert ("<td><code>seed</code></td>\n<td>integer (&gt;= 0)</td>\n<td>0</td>\n"
            "<td>every random draw derives from it</td>\n<td>42</td>") in dom
    assert "<td><code>cbba</code></td>" in dom and "<code>comm_range</code>" in dom
    looks_rendered(tmp_path / "missions.png")


def test_the_python_api_page_renders(site: Path, browser: str, tmp_path: Path) -> None:
    """The API page in Chromium: the functions and classes made from the docstrings."""
    dom = render(browser, site / "reference" / "python" / "index.html", tmp_path / "api.png")
    assert 'id="astralis_des.load_mission"' in dom
    assert 'id="astralis_des.Simulation"' in dom
    assert "Read a mission file" in dom  # load_mission's docstring
    assert ":class:" not in dom  # Sphinx roles turned into code (tools/docs_site/rst_roles.py)
    looks_rendered(tmp_path / "api.png")
