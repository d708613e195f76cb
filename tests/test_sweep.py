"""Sweeps (``fixplan.sweep``, ``fixplan sweep``): designs, equality with serial solves on a real
Dask cluster, failing cases kept in their rows, resumption, command-line errors."""

import dataclasses
import errno
import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import fixplan
from fixplan.design import CASE, SERIAL, Range, grid, latin_hypercube
from fixplan.errors import InvalidArgumentError
from fixplan.io.cli import EXIT_INVALID_INPUT, EXIT_OK, main
from fixplan.io.problem_file import load_problem
from fixplan.io.sweep_table import read_table
from fixplan.planner.planner import Planner

FIXTURE = Path(__file__).resolve().parents[1] / "problems" / "fixture-321.toml"
NUMBERS = ["objective_value", "safety_factor", "safety_factor[slot-feed-plus-x]"]
#: Six cases varying the top clamp's friction (a new planner per case) and the first load; the
#: third has a friction coefficient that the file reader rejects.
CASES = pd.DataFrame(
    {
        "contacts[6].mu": [0.2, 0.25, -0.1, 0.3, 0.35, 0.4],
        "loads[0].force[0]": [200.0, 230.0, 250.0, 260.0, 280.0, 300.0],
    }
)


@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2, processes=True, threads_per_worker=1, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client


def independent_plan(mu: float, feed: float):
    """The plan of the fixture with the top clamp's mu and the first load's x force changed,
    built without the sweep."""
    problem = load_problem(FIXTURE).problem
    contacts = list(problem.contacts)
    contacts[6] = dataclasses.replace(contacts[6], mu=mu)
    loads = list(problem.loads)
    force = loads[0].force.copy()
    force[0] = feed
    loads[0] = dataclasses.replace(loads[0], force=force)
    return Planner(dataclasses.replace(problem, contacts=contacts, loads=loads)).solve()


def test_a_cluster_sweep_equals_serial_solves_and_records_the_failing_case(client):
    table = fixplan.sweep.run(FIXTURE, CASES, client=client, chunk_size=2)
    assert table[CASE].tolist() == list(range(6))
    assert table["status"].tolist() == ["optimal"] * 2 + ["invalid input"] + ["optimal"] * 3
    assert "contacts[6].mu: expected a number >= 0, got -0.1" in table.loc[2, "message"]
    assert np.isnan(table.loc[2, NUMBERS].to_numpy(float)).all()
    for case in (0, 1, 3, 4, 5):
        plan = independent_plan(*CASES.loc[case])
        assert table.loc[case, "objective_value"] == plan.objective_value
        assert table.loc[case, "safety_factor"] == plan.safety_factor
        assert table.loc[case, "critical_load"] == plan.critical_load
        for name, value in plan.safety_factors.items():
            assert table.loc[case, f"safety_factor[{name}]"] == value


def test_a_sweep_of_loads_gives_the_same_numbers_on_a_cluster_as_in_process(client):
    variations = "loads[0].force[0]=150:350:8"
    serial = fixplan.sweep.run(FIXTURE, variations, client=SERIAL, chunk_size=3)
    spread = fixplan.sweep.run(FIXTURE, variations, client=client, chunk_size=3)
    assert spread.drop(columns="solve_time").equals(serial.drop(columns="solve_time"))
    assert (serial["status"] == "optimal").all()
    # Later cases of a chunk re-solve its first case's planner: fresh solves agree to rounding.
    for case in (5, 7):
        plan = independent_plan(0.25, float(serial.loc[case, "loads[0].force[0]"]))
        assert serial.loc[case, "objective_value"] == pytest.approx(plan.objective_value, rel=1e-9)


def test_a_resumed_sweep_keeps_finished_cases_and_solves_only_the_rest(tmp_path):
    table_path = tmp_path / "sweep.csv"
    full = fixplan.sweep.run(FIXTURE, CASES, client=SERIAL, chunk_size=2, table=table_path)
    assert read_table(table_path).sort_values(CASE, ignore_index=True).equals(full)
    lines = table_path.read_text().splitlines(keepends=True)
    interrupted = [lines[0], *lines[1:3], lines[3][:20]]  # two rows and a cut one
    table_path.write_text("".join(interrupted))
    finished = set(read_table(table_path)[CASE])
    assert len(finished) == 2
    calls = []
    resumed = fixplan.sweep.run(
        FIXTURE, CASES, client=SERIAL, chunk_size=2, table=table_path, resume=table_path,
        progress=lambda done, total: calls.append((done, total)),
    )  # fmt: skip
    assert calls[-1] == (4, 4)
    assert resumed.drop(columns="solve_time").equals(full.drop(columns="solve_time"))
    assert read_table(table_path).sort_values(CASE, ignore_index=True).equals(resumed)


def test_resuming_from_the_table_of_another_sweep_is_refused(tmp_path):
    table_path = tmp_path / "sweep.csv"
    fixplan.sweep.run(FIXTURE, CASES[:2], client=SERIAL, table=table_path)
    other = CASES[:2].assign(**{"contacts[6].mu": [0.3, 0.3]})
    with pytest.raises(InvalidArgumentError, match="case 0 has"):
        fixplan.sweep.run(FIXTURE, other, client=SERIAL, resume=table_path)


def test_a_grid_is_the_cartesian_product_with_the_last_key_fastest():
    cases = grid(
        [Range(key="a", start=0, stop=1, count=3), Range(key="b", start=5, stop=6, count=2)]
    )
    assert cases.index.name == CASE
    assert cases.to_numpy().tolist() == [[0, 5], [0, 6], [0.5, 5], [0.5, 6], [1, 5], [1, 6]]


@pytest.mark.parametrize("samples", [1, 7, 50])
def test_a_latin_hypercube_has_one_case_in_every_stratum_of_every_range(samples):
    ranges = [Range(key="mu", start=0.1, stop=0.5), Range(key="x", start=-0.06, stop=0.02)]
    cases = latin_hypercube(ranges, samples=samples, seed=3)
    assert len(cases) == samples
    for r in ranges:
        fraction = (cases[r.key].to_numpy() - r.start) / (r.stop - r.start)
        assert ((fraction >= 0) & (fraction <= 1)).all()
        assert sorted(np.floor(fraction * samples).astype(int)) == list(range(samples))
    assert latin_hypercube(ranges, samples=samples, seed=3).equals(cases)
    if samples > 1:
        assert not latin_hypercube(ranges, samples=samples, seed=4).equals(cases)


def test_integer_keys_vary_as_integers():
    table = fixplan.sweep.run(FIXTURE, "defaults.facets=4:8:2", client=SERIAL)
    assert table["status"].tolist() == ["optimal", "optimal"]
    assert table.loc[0, "objective_value"] != table.loc[1, "objective_value"]


def test_the_command_line_writes_tables_and_figures(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["sweep", str(FIXTURE), "--vary", "body.mass=-1:3:2", "--vary",
            "contacts[7].position[0]=-0.04:0.04:2", "--out", str(out), "--workers", "0"]  # fmt: skip
    assert main([*argv, "--json"]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["statuses"] == {"optimal": 2, "invalid input": 2}
    table = read_table(out / "sweep.parquet")
    assert table.equals(read_table(out / "sweep.csv"))
    assert table["body.mass"].tolist() == [-1.0, -1.0, 3.0, 3.0]
    assert sorted(p.name for p in (out / "figures").iterdir()) == [
        "objective-vs-body-mass.png", "objective-vs-contacts-7-position-0.png"]  # fmt: skip
    assert main(argv) == EXIT_INVALID_INPUT  # the folder holds a sweep: resume it or move on
    assert "--resume" in capsys.readouterr().err
    assert main([*argv, "--resume", str(out / "sweep.csv")]) == EXIT_OK
    assert "status     invalid input 2, optimal 2" in capsys.readouterr().out


def test_the_command_line_sends_the_cases_to_an_existing_scheduler(client, tmp_path, capsys):
    address = client.scheduler.address
    argv = ["sweep", str(FIXTURE), "--vary", "contacts[6].mu=0.2:0.3:3", "--out",
            str(tmp_path / "out"), "--scheduler", address, "--json"]  # fmt: skip
    assert main(argv) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["where"] == f"on {address}"
    assert summary["statuses"] == {"optimal": 3}
    serial = fixplan.sweep.run(FIXTURE, "contacts[6].mu=0.2:0.3:3", client=SERIAL)
    table = read_table(tmp_path / "out" / "sweep.csv")
    assert table.drop(columns="solve_time").equals(serial.drop(columns="solve_time"))


@pytest.mark.parametrize(
    ("vary", "extra", "message"),
    [
        ("contacts[1].mu=0.2..0.4", [], "expected KEY=start:stop:count"),
        ("contacts[1].mu=0.2:0.4", [], "a grid needs a count"),
        ("contacts[1].mu=0.2:0.4:3", ["--method", "lhs", "--samples", "4"], "takes no count"),
        ("contacts[1].mu=0.2:0.4:3", ["--samples", "4"], "samples is for method 'lhs'"),
        ("contacts[9].mu=0.2:0.4:3", [], "contacts[9]: contacts has 8 entries (indices 0–7)"),
        ("contacts[1].muu=0.2:0.4:3", [], "contacts[1].muu: unknown key; did you mean 'mu'?"),
        ("contacts[1].role=0:1:2", [], "holds str 'locator'; only numbers vary"),
        ("bodyy.mass=1:2:2", [], "bodyy: the file has no such table or array"),
        ("contacts.1.mu=1:2:2", [], "not a key path"),
        ("contacts[1].mu=0.2:0.4:3", ["--workers", "100000"], "--workers must be from 0 to"),
        ("contacts[1].mu=0.2:0.4:3", ["--workers", "-1"], "--workers must be from 0 to"),
    ],
)
def test_bad_variations_are_invalid_input_with_a_clear_message(
    tmp_path, capsys, vary, extra, message
):
    argv = ["sweep", str(FIXTURE), "--vary", vary, "--out", str(tmp_path / "out"), *extra]
    assert main(argv) == EXIT_INVALID_INPUT
    err = capsys.readouterr().err
    assert message in err
    assert "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_an_output_folder_that_cannot_be_made_is_invalid_input(tmp_path, capsys, monkeypatch):
    """``--out`` where the folder cannot be made although its parent looks writable (/proc/x,
    as root, ended in an unexpected error): here a read-only file system."""

    def read_only(self, *args, **kwargs):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(self))

    monkeypatch.setattr(Path, "mkdir", read_only)
    argv = ["sweep", str(FIXTURE), "--vary", "contacts[1].mu=0.2:0.4:3", "--out",
            str(tmp_path / "out"), "--workers", "0"]  # fmt: skip
    assert main(argv) == EXIT_INVALID_INPUT
    assert "cannot make it: Read-only file system" in capsys.readouterr().err


def test_a_local_cluster_of_more_workers_than_the_machine_runs_is_refused():
    with pytest.raises(InvalidArgumentError, match="workers must be an integer from 1 to"):
        fixplan.sweep.run(FIXTURE, "contacts[6].mu=0.2:0.3:3", workers=10**5)
