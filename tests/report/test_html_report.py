"""The HTML report: one self-contained page with every section and decodable embedded images."""

import base64
import re

import pytest

from conftest import needs_chromium
from turntable_pin import TurntableErrors
from turntable_pin.measurement.diagnosis import diagnose_measurements
from turntable_pin.measurement.simulation import simulate_measurements
from turntable_pin.report.html_report import diagnosis_html, write_report
from turntable_pin.viewer.browser import check_page_images


@pytest.mark.slow
def test_report_tells_the_whole_story(tmp_path):
    sim = simulate_measurements(
        TurntableErrors.from_arcsec(deps_y=4), {"backlash": {"b1": 3.0, "b2": -2.0}}, seed=5
    )
    diagnosis = diagnose_measurements(sim.data)
    page = diagnosis_html(diagnosis, title="t")
    headings = ("1. The data", "2. The base model", "3. Where the base model fails",
                "4. Diagnosis", "5. Add it and watch the error fall", "6. Parameters")  # fmt: skip
    assert all(h in page for h in headings)
    assert "backlash" in page and "dphi_y1 + deps_y" in page
    images = re.findall(r'src="data:image/png;base64,([^"]+)"', page)
    assert len(images) == 5  # data; base residuals, harmonics; the same before/after
    assert all(base64.b64decode(i)[:4] == b"\x89PNG" for i in images)
    assert "http://" not in page and "https://" not in page
    path = write_report(diagnosis, tmp_path / "r.html", title="t")
    assert path.read_text() == page


def test_clean_data_report_has_no_after_section():
    page = diagnosis_html(diagnose_measurements(simulate_measurements(seed=2).data))
    assert "5. Add it" not in page and "missing effect: none" in page


@pytest.mark.slow
@needs_chromium
def test_report_opens_in_the_browser_and_every_image_loads(tmp_path):
    sim = simulate_measurements(
        TurntableErrors.from_arcsec(dalpha_x1=3), {"gravity_sag": {"k": 4.0}}, seed=11
    )
    path = write_report(diagnose_measurements(sim.data), tmp_path / "report.html")
    report = check_page_images(path)
    assert report.n_images == len(re.findall(r"<img ", path.read_text())) == 5
    assert report.all_loaded, report.failed
