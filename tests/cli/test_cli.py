"""The command line: output on success, one-line errors and exit code 2 on bad input."""

import pytest
from typer.testing import CliRunner

from pushctl.cli import app

runner = CliRunner()


def test_info_shows_computed_mass_properties():
    result = runner.invoke(app, ["info", "--object", "wedge"])
    assert result.exit_code == 0, result.output
    assert "5.9184e-04" in result.output  # wedge I_z [kg·m²], computed from its geometry
    assert "26.67 mm" in result.output  # centre of mass 80/3 mm high


@pytest.mark.parametrize(
    ("args", "fragment"),
    [(["info", "--object", "sphere"], "cube, wedge"), (["info", "--arm", "ur5"], "panda")],
)
def test_bad_names_give_one_line_and_exit_2(args, fragment):
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert fragment in result.output
    assert "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1


def test_missing_object_file_is_reported(tmp_path):
    result = runner.invoke(app, ["info", "--object", str(tmp_path / "nope.toml")])
    assert result.exit_code == 2
    assert "nope.toml" in result.output
