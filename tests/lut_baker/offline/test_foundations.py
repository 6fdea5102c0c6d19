"""Published foundations against eq. 2 (lut_baker.offline.foundations): one product analysed,
its CSV (exact header, the measured rows, finite values), its figure and the report's sections;
unknown products and missing files are one clear error."""

from pathlib import Path

import numpy as np
import pytest

from lut_baker.offline import foundations as FD
from lut_baker.offline.measured.inplane_fit import FitModel

DATA = Path(__file__).parents[3] / "data" / "lanza2024"
HEADER = "theta_i_deg,theta_o_deg,measured_R,measured_G,measured_B,model_R,model_G,model_B"


@pytest.fixture(scope="module")
def matte():
    return FD.analyse("clarins_103", DATA)


def test_every_product_file_is_in_the_repository():
    for filename, finish in FD.PRODUCTS.values():
        assert (DATA / filename).is_file(), filename
        assert finish in ("matte", "dewy")
    assert ",".join(FD.CSV_COLUMNS) == HEADER


@pytest.mark.slow  # one product analysed, ~3 s
def test_an_analysis_fits_all_and_alternate_incidences(matte):
    assert matte.finish == "matte"
    assert matte.split == ((20.0, 40.0, 60.0), (30.0, 50.0, 70.0))
    assert matte.fit.fitted_deg == (20.0, 30.0, 40.0, 50.0, 60.0, 70.0)
    assert matte.held_out.fitted_deg == (20.0, 40.0, 60.0)
    assert set(matte.misses) == set(matte.split[0] + matte.split[1])
    rms, worst = matte.fit.error()
    assert 0.0 < rms < worst < 1.0  # the matte product is within tens of percent
    # The well-posed form of a matte product: P_d alone, reached from the full eq. 2 with
    # the tilt; every form tried is also fitted to alternate incidences.
    models = [fits.fit_model for fits, _ in matte.choice.steps]
    assert models[0] == FitModel() and models[-1] == FitModel(lobe=False, tilt=False)
    assert [h.fit_model for h in matte.held_out_steps] == models
    assert matte.untilted is None and matte.fit.tilt is None


@pytest.mark.slow  # one product analysed, ~3 s
def test_the_csv_has_the_exact_header_and_the_measured_rows(matte, tmp_path):
    path = FD.write_csv(matte, tmp_path / "p.csv")
    lines = path.read_text().splitlines()
    assert lines[0] == HEADER
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    assert table.shape == (115, 8)
    assert np.all(np.isfinite(table)) and np.all(table[:, 2:] > 0)
    np.testing.assert_allclose(table[:, 2:5], matte.data.rgb, rtol=1e-5)
    np.testing.assert_allclose(table[:, 5:], matte.fit.model, rtol=1e-5)


@pytest.mark.slow  # one product analysed, ~3 s
def test_the_figure_has_points_and_curves_per_incidence(matte):
    figure = FD.product_figure(matte)
    gids = {line.get_gid() for line in figure.axes[0].lines if line.get_gid()}
    for incidence in (20, 30, 40, 50, 60, 70):
        assert {f"model theta_i={incidence}", f"measured theta_i={incidence}",
                f"not determined theta_i={incidence}"} <= gids


@pytest.mark.slow  # one product analysed, ~3 s
def test_the_report_has_each_products_numbers(matte):
    text = FD.report([matte], {"clarins_103": "NOTE 103", "conclusion": "THE END"})
    assert text.startswith("# Published foundations against the paper's eq. 2")
    assert "## clarins_103 (matte)" in text and "NOTE 103" in text
    assert "## Conclusions" in text and "THE END" in text
    assert text.count("| R |") == 1 and text.count("| 70° |") == 1
    # The forms tried, each with its errors, tilt, starts and checks; the chosen one marked.
    rows = [line for line in text.splitlines() if line.startswith(("| eq. 2", "| P_d alone"))]
    assert len(rows) == len(matte.choice.steps)
    assert rows[0].startswith("| eq. 2 (P_d, P_s, n, eta per channel) + tilt |")
    assert "(at bound)" in rows[0] and "**failed**: the tilt ran to its bound" in rows[0]
    assert rows[-1].startswith("| P_d alone (no lobe) |") and rows[-1].endswith("**chosen** |")
    assert "Chosen form: P_d alone (no lobe)." in text


@pytest.mark.slow  # one product analysed, ~3 s
def test_the_report_lists_the_derived_presets(matte):
    """The thin-film preset each product implies (docs/model.md §4): the same entry as the
    runtime's file, in its own section with the absorption and gloss."""
    from lut_baker.offline import foundation_presets

    derived = FD.derived_presets([matte])
    stored = foundation_presets.read_presets()["clarins_103"]
    np.testing.assert_allclose(derived["clarins_103"]["absorption"], stored["absorption"],
                               rtol=1e-6)
    text = FD.report([matte], {"presets": "PRESET NOTE"}, derived)
    assert "## Presets for the model" in text and "PRESET NOTE" in text
    row = next(line for line in text.splitlines() if line.startswith("| clarins_103 |"))
    assert "Clarins 103 (matte, measured)" in row and f"{stored['absorption'][0]:.4f}" in row
    assert "## Presets for the model" not in FD.report([matte])


def test_unknown_products_and_missing_files_are_one_line(tmp_path):
    with pytest.raises(ValueError, match="unknown product 'x'"):
        FD.analyse("x", DATA)
    with pytest.raises(ValueError, match="no such file"):
        FD.analyse("clarins_103", tmp_path)


def test_the_notes_page_has_a_section_per_product_and_its_lines_join(tmp_path):
    """docs/foundations/notes.md holds the prose (not the code): one section per product, the
    presets' and the conclusion; a paragraph's lines join with single spaces."""
    notes = FD.read_notes(Path(__file__).parents[3] / "docs" / "foundations" / "notes.md")
    assert set(notes) == set(FD.PRODUCTS) | set(FD.NOTE_SECTIONS)
    assert all(text and "\n\n\n" not in text for text in notes.values())
    page = tmp_path / "notes.md"
    page.write_text("# Notes\n\nignored preamble\n\n## clarins_105\n\nOne\nparagraph.\n\n"
                    "Two.\n\n## conclusion\nEnd.\n")
    assert FD.read_notes(page) == {"clarins_105": "One paragraph.\n\nTwo.", "conclusion": "End."}


def test_a_note_for_no_section_or_no_file_is_an_error(tmp_path):
    page = tmp_path / "notes.md"
    page.write_text("## clarins_999\n\nA typo.\n")
    with pytest.raises(ValueError, match="'clarins_999' is neither a product"):
        FD.read_notes(page)
    with pytest.raises(ValueError, match="notes '.*absent.md'"):
        FD.read_notes(tmp_path / "absent.md")
