"""``ballenv-compile``: the env's and the common scenes' kernels into numba's cache ahead of the first
run, in processes side by side; clear errors for options that name nothing."""

import pytest

from ballenv import compile as ahead


def test_every_job_runs_a_known_function():
    assert len(ahead.JOBS) >= 3
    for function, argument in ahead.JOBS.values():
        assert function in (ahead._env, ahead._rings_on_floor) and argument is not None


def test_an_option_naming_no_job_is_an_error_listing_the_jobs(capsys):
    with pytest.raises(SystemExit):
        ahead.main(["--only", "teapot"])
    err = capsys.readouterr().err
    assert "--only 'teapot' names no job" in err and "env, pressure mode" in err


def test_jobs_below_one_is_an_error(capsys):
    with pytest.raises(SystemExit):
        ahead.main(["--jobs", "0"])
    assert "--jobs must be at least 1, got 0" in capsys.readouterr().err


def test_a_job_runs_in_its_own_process_and_reports_its_time(capsys):
    ahead.main(["--only", "env, pressure", "--jobs", "2"])
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "compiling the simulator: 1 job, 1 at once"
    assert out[1].startswith("[1/1] env, pressure mode: ") and out[1].endswith(" s")
    assert out[2].startswith("compiled in ")
