"""The Python module `codyna` against the command line (CTest: python.pytest, label python).

The module binds the same study calls the `codyna` command makes, so what it returns must be
the command line's output bit for bit (np.array_equal, never allclose):
  * every example's A, B, C, D, x0, u0, y0, xdot0 and names equal the CLI's NAME.mat, also
    discrete (Ts = 0.01) and by central differences on the cart-pendulum, along a trajectory,
    with held coordinates given as a dict, and for the linear closed loop (NAME_cl.mat);
  * the paper's example as scripts/demo.sh runs it (cart-pendulum, equilibrium): the CLI's MAT
    v7.3 export read by h5py gives the module's A, B, C, D, offsets and names (bits, and 1e-12
    relative), the CLI's modes table is modes_text, numpy's eig of its A the module's eigenvalues
    to 1e-12 of the spectral radius, and its closed loop's poles_cl (scipy.io) the module's poles;
  * Linearization.export writes the CLI's files (every variable of NAME.mat, the NAME.m text);
  * the cart-pendulum's closed loop (lqr=True, t_end=2) equals the CLI's HDF5 trajectory, and
    Simulation.save writes an HDF5 whose every dataset equals the CLI's;
  * a bad field raises codyna.ModelError (a ValueError) with the CLI's message, the file and
    the field path; a failed trim raises codyna.ConvergenceError; an unknown keyword raises
    TypeError naming it; a bad value raises ValueError naming the keyword;
  * codyna.lqr agrees with scipy.linalg.solve_continuous_are (K = R^-1 B' X, 1e-9 relative),
    codyna.place puts eig(A - B K) at the poles;
  * Ctrl+C (SIGINT) stops a long simulation within a second, as KeyboardInterrupt;
  * Study.sweep: the rod mass over 11 values with the LQR fixed: each variant's A, B, C, D equal
    its own Study.from_json(edited JSON).linearize() bit for bit, its closed-loop poles
    eig(A - B K) to 1e-10, K scipy's design on the nominal model; a Monte Carlo (seed 7, run
    with --simulate) equals the CLI's HDF5 file dataset by dataset and itself on 1 and 2
    threads, and the files it writes (HDF5, CSV, MAT and .m) are the CLI's bytes; the grid from
    Study.from_json with the values as a numpy array gives the same arrays; failed variants (status, reason, NaN
    rows); bad keywords (ValueError naming vary and the field, TypeError); the progress
    callback on the calling thread; a study stopped by its callback resumes from its journal
    into the uninterrupted run's bytes; SIGINT stops a sweep on 2 threads within a second;
  * examples/python/cart_pendulum_lqr.py runs and writes its PNG.

Environment (set by CTest): PYTHONPATH=build/python, CODYNA_BIN (the codyna command),
CODYNA_SOURCE_DIR (the source tree). Nothing is skipped: a missing piece fails.
"""
import glob
import json
import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest
import scipy.io
import scipy.linalg

import codyna

SOURCE_DIR = os.environ.get("CODYNA_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXAMPLES = sorted(glob.glob(os.path.join(SOURCE_DIR, "examples", "*.json")))
CART = os.path.join(SOURCE_DIR, "examples", "cart_pendulum.json")
PENDULUM = os.path.join(SOURCE_DIR, "examples", "pendulum.json")
# the folder this codyna was imported from, for child processes started elsewhere
CHILD_ENV = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(os.path.abspath(codyna.__file__))))


def codyna_bin():
    path = os.environ.get("CODYNA_BIN")
    assert path and os.access(path, os.X_OK), "CODYNA_BIN must name the codyna command (CTest sets it)"
    return path


def cli(*args, cwd=None, expect=0):
    """Runs the codyna command; returns (stdout, stderr)."""
    p = subprocess.run([codyna_bin(), *map(str, args)], cwd=cwd, capture_output=True, text=True)
    assert p.returncode == expect, "codyna %s: exit %d\n%s%s" % (" ".join(map(str, args)), p.returncode, p.stdout, p.stderr)
    return p.stdout, p.stderr


def mat_names(d, key):
    return [str(x[0]) if x.size else "" for x in d[key].ravel()]


def same(actual, expected):
    """Bit for bit: the same shape (empty matrices: the same size) and the same doubles."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    if actual.size == 0 and expected.size == 0:
        return True
    return actual.shape == expected.shape and np.array_equal(actual, expected)


def check_against_mat(lin, mat_path):
    d = scipy.io.loadmat(mat_path)
    for key in ("A", "B", "C", "D"):
        assert same(getattr(lin, key), d[key]), "%s differs from %s" % (key, mat_path)
    for key in ("x0", "u0", "y0", "xdot0"):
        assert same(getattr(lin, key), d[key].ravel()), "%s differs from %s" % (key, mat_path)
    assert lin.Ts == float(d["Ts"].ravel()[0])
    assert lin.state_names == mat_names(d, "state_names")
    assert lin.input_names == mat_names(d, "input_names")
    assert lin.output_names == mat_names(d, "output_names")
    return d


def mat_path(out_dir, stdout):
    mats = [l.split(" ", 1)[1] for l in stdout.splitlines() if l.startswith("wrote ") and l.endswith(".mat")]
    assert mats, stdout
    return os.path.join(out_dir, os.path.basename(mats[0])) if not os.path.isabs(mats[0]) else mats[0]


# ------------------------------------------------------------------------- linearize

def test_examples_exist():
    assert len(EXAMPLES) >= 10, EXAMPLES


def cli_messages(stderr, kind):
    prefix = "codyna: %s: " % kind
    return [l[len(prefix):] for l in stderr.splitlines() if l.startswith(prefix)]


@pytest.mark.parametrize("model", EXAMPLES, ids=[os.path.basename(m)[:-5] for m in EXAMPLES])
def test_linearize_equals_cli(model, tmp_path):
    # the model file's own study; three examples have no equilibrium to find (no Plant/In to hold
    # them): the CLI exits 2 and the module raises ConvergenceError with the same message, and both
    # are compared again at the initial point
    study = codyna.Study(model)
    p = subprocess.run([codyna_bin(), "linearize", model, "--out", str(tmp_path / "cli")], capture_output=True, text=True)
    options, flags = {}, []
    if p.returncode == 2:
        with pytest.raises(codyna.ConvergenceError) as e:
            study.linearize()
        assert cli_messages(p.stderr, "error") == [str(e.value)]
        assert not (tmp_path / "cli").exists() or not os.listdir(tmp_path / "cli")
        options, flags = {"operating_point": "initial"}, ["--operating-point", "initial"]
        p = subprocess.run([codyna_bin(), "linearize", model, "--out", str(tmp_path / "cli"), *flags],
                           capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr
    lin = study.linearize(**options)
    check_against_mat(lin, mat_path(tmp_path / "cli", p.stdout))
    assert lin.A.dtype == np.float64 and lin.A.shape == (len(lin.state_names),) * 2
    ev = lin.eigenvalues()
    assert ev.dtype == np.complex128 and ev.shape == (lin.A.shape[0],)
    assert lin.operating_point["kind"] == options.get("operating_point", lin.operating_point["kind"])
    # the messages the CLI prints are the ones the module returns
    assert lin.warnings == cli_messages(p.stderr, "warning")
    assert study.notes + lin.notes == cli_messages(p.stderr, "note")


@pytest.mark.parametrize("options,flags", [
    (dict(discrete=0.01), ["--discrete", "0.01"]),
    (dict(method="fd-central"), ["--method", "fd-central"]),
    (dict(operating_point="initial", method="fd-forward", discrete=0.05), ["--operating-point", "initial", "--method", "fd-forward", "--discrete", "0.05"]),
], ids=["discrete", "fd-central", "initial-fd-forward-discrete"])
def test_linearize_options_equal_cli(options, flags, tmp_path):
    stdout, _ = cli("linearize", CART, "--out", tmp_path, *flags)
    lin = codyna.Study(CART).linearize(**options)
    check_against_mat(lin, tmp_path / "cart_pendulum.mat")
    if "discrete" in options:
        assert lin.Ts == options["discrete"]
    assert lin.method == options.get("method", "exact")


def test_hold_dict_is_exact(tmp_path):
    # a dict's values go to the core with 17 significant digits: the same double as the flag's
    value = 0.1 + 0.2  # 0.30000000000000004
    cli("linearize", PENDULUM, "--out", tmp_path, "--operating-point", "initial", "--hold", "pivot=%r" % value)
    lin = codyna.Study(PENDULUM).linearize(operating_point="initial", hold={"pivot": value})
    check_against_mat(lin, tmp_path / "pendulum.mat")
    assert lin.operating_point["coordinates"]["pivot"] == value


def test_plant_keywords_equal_cli(tmp_path):
    cli("linearize", PENDULUM, "--out", tmp_path, "--outputs", "theta,tip_x", "--operating-point", "initial")
    lin = codyna.Study(PENDULUM).linearize(outputs=["theta", "tip_x"], operating_point="initial")
    check_against_mat(lin, tmp_path / "pendulum.mat")
    assert lin.output_names == ["theta", "tip_x"]


def test_trajectory_equals_cli(tmp_path):
    cli("linearize", PENDULUM, "--out", tmp_path, "--trajectory", "0.5", "--trajectory-step", "0.05")
    lin = codyna.Study(PENDULUM).linearize(trajectory=0.5, trajectory_step=0.05)
    d = scipy.io.loadmat(tmp_path / "pendulum.mat")
    assert lin.trajectory and len(lin.times) == 11
    assert np.array_equal(lin.times, d["t"].ravel())
    for key in ("A", "B", "C", "D"):
        assert np.array_equal(getattr(lin, key), np.moveaxis(d[key].reshape(getattr(lin, key).shape[1:] + (-1,)), -1, 0)), key
    for key in ("x0", "u0", "y0", "xdot0"):
        assert np.array_equal(getattr(lin, key), d[key].T), key


def test_closed_loop_equals_cli(tmp_path):
    cli("linearize", CART, "--out", tmp_path, "--closed-loop", "--lqr")
    lin = codyna.Study(CART).linearize(closed_loop=True, lqr=True)
    check_against_mat(lin, tmp_path / "cart_pendulum.mat")
    cl = lin.closed_loop
    d = scipy.io.loadmat(tmp_path / "cart_pendulum_cl.mat")
    for key in ("A", "B", "C", "D"):
        assert same(getattr(cl, key), d[key + "cl"]), key
    assert np.all(cl.poles().real < 0)
    assert codyna.Study(CART).linearize().closed_loop is None


def h5_matrix(f, key):
    """A MAT v7.3 double as MATLAB sees it (HDF5 holds MATLAB's column-major layout: transposed)."""
    return np.array(f[key], dtype=float).T


def h5_names(f, key):
    """A MAT v7.3 cellstr: references to uint16 character arrays."""
    return ["".join(map(chr, np.array(f[ref]).ravel())) for ref in np.array(f[key]).ravel()]


def relative_gap(actual, expected):
    """max |actual - expected| / max |expected| (the absolute gap where expected is all zeros)."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape, (actual.shape, expected.shape)
    if actual.size == 0:
        return 0.0
    gap, scale = np.max(np.abs(actual - expected)), np.max(np.abs(expected))
    return gap / scale if scale > 0 else gap


def matched(actual, expected):
    """expected reordered to pair each of actual's eigenvalues with its nearest (one to one)."""
    left, order = list(expected), []
    for a in actual:
        k = int(np.argmin([abs(a - e) for e in left]))
        order.append(left.pop(k))
    return np.array(order)


def test_cli_and_python_agree_on_the_papers_example(tmp_path):
    # the demo's run (scripts/demo.sh): codyna linearize on the paper's cart-pendulum at its
    # equilibrium, through the command, its MAT v7.3 (HDF5) export read by h5py, against the
    # module's Study.linearize: A, B, C, D, offsets and names from the same core, so the same bits
    # (the 1e-12 relative bound is asserted too, and implied); the eigenvalues: the modes table the
    # command prints is the module's modes_text, and numpy's eig of the command's A agrees with
    # Linearization.eigenvalues() to 1e-12 of the spectral radius (two eigenvalue codes)
    stdout, _ = cli("linearize", CART, "--operating-point", "equilibrium", "--mat-version", "7.3", "--out", tmp_path / "h5")
    lin = codyna.Study(CART).linearize(operating_point="equilibrium")
    with h5py.File(tmp_path / "h5" / "cart_pendulum.mat", "r") as f:
        assert f["A"].attrs["MATLAB_class"] == b"double"
        for key in ("A", "B", "C", "D"):
            expected = h5_matrix(f, key)
            assert relative_gap(getattr(lin, key), expected) <= 1e-12, key
            assert np.array_equal(getattr(lin, key), expected), key
        for key in ("x0", "u0", "y0", "xdot0"):
            expected = np.array(f[key], dtype=float).ravel()
            assert relative_gap(getattr(lin, key), expected) <= 1e-12, key
            assert np.array_equal(getattr(lin, key), expected), key
        assert lin.Ts == float(np.array(f["Ts"]).ravel()[0]) == 0.0
        for key in ("state_names", "input_names", "output_names"):
            assert getattr(lin, key) == h5_names(f, key), key
        A = h5_matrix(f, "A")
    assert lin.A.shape == (4, 4) and lin.state_names == ["cart_slider", "rod_pivot", "cart_slider_dot", "rod_pivot_dot"]
    ev = lin.eigenvalues()
    assert ev.shape == (4,) and np.max(np.abs(ev.real)) > 3  # the inverted pendulum's unstable pair +-3.13
    assert relative_gap(ev, matched(ev, np.linalg.eigvals(A))) <= 1e-12
    assert "\n" + lin.modes_text + "\n" in stdout

    # the closed loop with the model file's LQR: its poles are in NAME_cl.mat (MAT v5, scipy.io)
    # as the command computed them, and must be the module's to the bit
    stdout, _ = cli("linearize", CART, "--operating-point", "equilibrium", "--closed-loop", "--out", tmp_path / "cl")
    cl = codyna.Study(CART).linearize(operating_point="equilibrium", closed_loop=True).closed_loop
    d = scipy.io.loadmat(tmp_path / "cl" / "cart_pendulum_cl.mat")
    for key in ("A", "B", "C", "D"):
        assert relative_gap(getattr(cl, key), d[key + "cl"]) <= 1e-12, key
        assert np.array_equal(getattr(cl, key), d[key + "cl"]), key
    poles = d["poles_cl"][:, 0] + 1j * d["poles_cl"][:, 1]
    assert poles.shape == (4,) and np.all(poles.real < 0)
    assert relative_gap(cl.poles(), poles) <= 1e-12
    assert np.array_equal(cl.poles(), poles)
    assert "\n" + cl.poles_text + "\n" in stdout


def test_export_writes_the_cli_files(tmp_path):
    cli("linearize", CART, "--out", tmp_path / "cli", "--closed-loop", "--lqr")
    lin = codyna.Study(CART).linearize(closed_loop=True, lqr=True)
    written = lin.export(tmp_path / "py")
    assert [os.path.basename(p) for p in written] == [
        "cart_pendulum.mat", "cart_pendulum.m", "cart_pendulum_cl.mat", "cart_pendulum_cl.m",
        "cart_pendulum_cl_step.csv", "cart_pendulum_cl_freq.csv"]
    for name in ("cart_pendulum.mat", "cart_pendulum_cl.mat"):
        a, b = scipy.io.loadmat(tmp_path / "py" / name), scipy.io.loadmat(tmp_path / "cli" / name)
        assert sorted(k for k in a if not k.startswith("__")) == sorted(k for k in b if not k.startswith("__"))
        for k in a:
            if k.startswith("__") or k == "info":
                continue
            if a[k].dtype.kind in "fiu":
                assert a[k].shape == b[k].shape and np.array_equal(a[k], b[k]), (name, k)
            else:
                assert str(a[k]) == str(b[k]), (name, k)
    for name in ("cart_pendulum.m", "cart_pendulum_cl.m", "cart_pendulum_cl_step.csv", "cart_pendulum_cl_freq.csv"):
        assert (tmp_path / "py" / name).read_text() == (tmp_path / "cli" / name).read_text(), name
    check_against_mat(lin, written[0])


def test_export_refuses_to_replace_the_model(tmp_path):
    model = tmp_path / "pendulum.json"
    model.write_text(open(PENDULUM).read())
    lin = codyna.Study(model).linearize(name="pendulum")
    (tmp_path / "pendulum.m").write_text("% a user's script\n")
    with pytest.raises(ValueError):
        lin.export(tmp_path)
    assert (tmp_path / "pendulum.m").read_text() == "% a user's script\n"


def test_from_json_equals_file():
    text = open(PENDULUM).read()
    a = codyna.Study(PENDULUM).linearize()
    b = codyna.Study.from_json(text).linearize()
    for key in ("A", "B", "C", "D", "x0", "u0", "y0", "xdot0"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key


def test_model_info():
    info = codyna.Study(CART).model_info()
    assert info["name"] == "cart_pendulum" and info["dof"] == 2
    assert [b["name"] for b in info["bodies"]] == ["cart", "rod"] or len(info["bodies"]) == 2
    assert info["plant_inputs"] == ["force"]
    assert info["plant_outputs"] == ["h", "theta"]
    assert [a["name"] for a in info["actuators"]] == ["force"]
    assert [s["name"] for s in info["sensors"]] == ["h", "theta", "h_dot", "theta_dot"]
    assert len(info["coordinates"]) == 2 and len(info["rates"]) == 2
    assert info["controller"] == "lqr"
    four_bar = codyna.Study(os.path.join(SOURCE_DIR, "examples", "four_bar.json")).model_info()
    assert four_bar["constraints"] and four_bar["dof"] == 1 and four_bar["rate_dof"] == 1
    # rolling (non-holonomic): 5 coordinates, 3 rates, and a plant of 5 + 3 states
    plate = codyna.Study(os.path.join(SOURCE_DIR, "examples", "ball_plate.json"))
    info = plate.model_info()
    assert info["dof"] == 5 and info["rate_dof"] == 3 and info["constraint_equations"] == 3
    lin = plate.linearize()
    assert lin.A.shape == (8, 8) and lin.B.shape == (8, 2)


# ---------------------------------------------------------------------------- errors

def test_bad_field_raises_model_error(tmp_path):
    model = json.load(open(PENDULUM))
    model["bodies"][0]["mass"] = -10.0
    path = tmp_path / "negative_mass.json"
    path.write_text(json.dumps(model))
    _, stderr = cli("linearize", path, "--out", tmp_path / "out", expect=1)
    with pytest.raises(codyna.ModelError) as e:
        codyna.Study(path).linearize()
    assert isinstance(e.value, ValueError)
    message = str(e.value)
    assert "/bodies/0/mass" in message and "negative_mass.json" in message, message
    assert e.value.path == "/bodies/0/mass" and e.value.file == str(path)
    assert stderr.strip() == "codyna: error: " + message  # the CLI's message
    assert not (tmp_path / "out").exists()


def test_malformed_json_raises_model_error():
    with pytest.raises(codyna.ModelError) as e:
        codyna.Study.from_json('{"codyna_model": 1, "bodies": [}')
    assert "<json>" in str(e.value)


def test_failed_trim_raises_convergence_error(tmp_path):
    model = os.path.join(SOURCE_DIR, "tests", "data", "trim_underactuated.json")
    _, stderr = cli("linearize", model, "--operating-point", "trim", "--out", tmp_path, expect=2)
    with pytest.raises(codyna.ConvergenceError) as e:
        codyna.Study(model).linearize(operating_point="trim")
    assert isinstance(e.value, RuntimeError)
    assert "/analysis/operating_point: trim: not converged" in str(e.value)
    assert stderr.strip() == "codyna: error: " + str(e.value)


def test_unknown_keyword_raises_type_error():
    study = codyna.Study(PENDULUM)
    with pytest.raises(TypeError, match="operating_pont"):
        study.linearize(operating_pont="initial")
    with pytest.raises(TypeError, match="t_ned"):
        study.simulate(t_ned=1)
    with pytest.raises(TypeError, match="discrete"):
        study.linearize(discrete="0.01")  # a str where a number goes


def test_bad_values_name_the_keyword():
    study = codyna.Study(PENDULUM)
    with pytest.raises(ValueError, match="^discrete"):
        study.linearize(discrete=-1)
    with pytest.raises(ValueError, match="method"):
        study.linearize(method="exactly")
    with pytest.raises(ValueError, match="inputs"):
        study.linearize(inputs=["nothing"])
    with pytest.raises(ValueError, match="t_end"):
        study.simulate(t_end=-1)
    with pytest.raises(ValueError, match="hold"):
        study.linearize(hold={"pivot": float("nan")})


# ---------------------------------------------------------------------------- simulate

def read_h5(path):
    """Every dataset of an HDF5 file, by path."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                out[name] = obj[()]
        f.visititems(visit)
        out["@status"] = dict(f["status"].attrs)
    return out


@pytest.fixture(scope="module")
def cart_lqr(tmp_path_factory):
    """The cart-pendulum's closed loop with an LQR for 2 s: the CLI's HDF5 and the module's run."""
    d = tmp_path_factory.mktemp("cart_lqr")
    stdout, _ = cli("simulate", CART, "--lqr", "--t-end", "2", "--quiet", "--out", d / "cli.h5", "--csv", d / "cli.csv")
    run = codyna.Study(CART).simulate(lqr=True, t_end=2)
    return d, stdout, run


def test_closed_loop_simulation_equals_cli(cart_lqr):
    d, _, run = cart_lqr
    ref = read_h5(d / "cli.h5")
    assert run.completed and run.failure == ""
    assert np.array_equal(run.t, ref["time"])
    for key in ("q", "v", "u", "y", "xc"):
        assert same(getattr(run, key), ref[key]), key
    assert np.array_equal(run.x, np.hstack([ref["q"], ref["v"]]))
    assert run.output_names == [s.decode() for s in ref["names/outputs"]]
    assert run.x_names == [s.decode() for s in ref["names/q"]] + [s.decode() for s in ref["names/v"]]
    assert run.y_linear is None
    assert run.t[-1] == 2.0


def test_lqr_gain_is_the_clis(cart_lqr):
    _, stdout, run = cart_lqr
    line = [l for l in stdout.splitlines() if l.startswith("K(force) = [")][0]
    K = np.array([float(x) for x in line[len("K(force) = ["):-1].split()])
    assert np.array_equal(run.lqr_gain.ravel(), K)  # printed with 17 digits: exact
    assert run.controller_source == "lqr"
    assert np.all(run.lqr_poles.real < 0)


def test_save_writes_the_cli_hdf5(cart_lqr, tmp_path):
    d, _, run = cart_lqr
    run.save(tmp_path / "py.h5", csv=tmp_path / "py.csv")
    a, b = read_h5(tmp_path / "py.h5"), read_h5(d / "cli.h5")
    assert sorted(a) == sorted(b)
    for key in a:
        if isinstance(a[key], np.ndarray) and a[key].dtype.kind == "f":
            assert a[key].shape == b[key].shape and np.array_equal(a[key], b[key]), key
        else:
            assert str(a[key]) == str(b[key]), key
    assert (tmp_path / "py.csv").read_text() == (d / "cli.csv").read_text()


def test_save_refuses_to_replace_the_model(cart_lqr, tmp_path):
    _, _, run = cart_lqr
    with pytest.raises(ValueError):
        run.save(CART)
    (tmp_path / "notes.h5").write_text("not codyna's")
    with pytest.raises(ValueError):
        run.save(tmp_path / "notes.h5")
    assert (tmp_path / "notes.h5").read_text() == "not codyna's"


def test_compare_linear_equals_cli(tmp_path):
    cli("simulate", PENDULUM, "--compare-linear", "--t-end", "1", "--quiet", "--out", tmp_path / "cli.h5")
    run = codyna.Study(PENDULUM).simulate(compare_linear=True, t_end=1)
    ref = read_h5(tmp_path / "cli.h5")
    assert np.array_equal(run.y, ref["y"]) and np.array_equal(run.y_linear, ref["y_linear"])
    gap = run.linear_gap
    assert gap["max_abs"]["theta"] == np.abs(run.y[:, 0] - run.y_linear[:, 0]).max()


def interrupt_a_second_in(child, *args):
    """Runs the Python code `child` with `args`; once it prints "start", waits a second and sends
    SIGINT: it must print "interrupted after T s" with T under 8 s (it stopped about a second in,
    not after its whole run; margins for a loaded machine) within 5 s of the signal, exit 0."""
    p = subprocess.Popen([sys.executable, "-c", child, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env=CHILD_ENV)
    assert p.stdout.readline().strip() == "start"
    time.sleep(1.0)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    waited = time.monotonic() - sent
    assert p.returncode == 0, err
    assert out.startswith("interrupted after"), out + err
    assert float(out.split()[2]) < 8, out
    assert waited < 5.0, waited


def test_ctrl_c_interrupts_a_simulation():
    # a run of hours (the double pendulum, open loop, 20000 s), interrupted after a second
    child = r"""
import sys, time, codyna
study = codyna.Study(sys.argv[1])
print("start", flush=True)
t0 = time.monotonic()
try:
    study.simulate(open_loop=True, t_end=20000)
    print("completed")
except KeyboardInterrupt:
    print("interrupted after %.3f s" % (time.monotonic() - t0), flush=True)
"""
    # stopped about a second in, not after the whole run (about 25 s alone)
    interrupt_a_second_in(child, os.path.join(SOURCE_DIR, "examples", "double_pendulum.json"))


def test_a_simulation_releases_the_gil():
    # another Python thread keeps running while a run of about a second goes on
    import threading
    study = codyna.Study(os.path.join(SOURCE_DIR, "examples", "double_pendulum.json"))
    done, runs = threading.Event(), []
    worker = threading.Thread(target=lambda: (runs.append(study.simulate(open_loop=True, t_end=1000)), done.set()))
    start = time.monotonic()
    worker.start()
    beats = [start]
    while not done.is_set():
        beats.append(time.monotonic())
    worker.join()
    duration = time.monotonic() - start
    gaps = np.diff(beats)
    assert runs and runs[0].completed
    assert duration > 0.3, duration  # long enough to tell
    assert gaps.max() < 0.1 * duration, (gaps.max(), duration)  # never blocked for the run


# ---------------------------------------------------------------------------- control

def test_lqr_against_scipy():
    lin = codyna.Study(CART).linearize()
    A, B = lin.A, lin.B
    Q, R = np.diag([10.0, 100.0, 1.0, 1.0]), np.array([[0.01]])
    K, X, poles = codyna.lqr(A, B, Q, R)
    X_scipy = scipy.linalg.solve_continuous_are(A, B, Q, R)
    K_scipy = np.linalg.solve(R, B.T @ X_scipy)
    assert np.abs(K - K_scipy).max() <= 1e-9 * np.abs(K_scipy).max()
    assert np.abs(X - X_scipy).max() <= 1e-9 * np.abs(X_scipy).max()
    assert np.allclose(np.sort_complex(poles), np.sort_complex(np.linalg.eigvals(A - B @ K)), rtol=1e-9, atol=0)
    Kd, _, pd = codyna.lqr(scipy.linalg.expm(A * 0.01), B * 0.01, Q, R, discrete=True)
    assert np.all(np.abs(pd) < 1)
    with pytest.raises(ValueError):
        codyna.lqr(A, B, Q[:2, :2], R)


def test_place():
    lin = codyna.Study(CART).linearize()
    A, B = lin.A, lin.B
    poles = np.array([-1.0, -2.0, -3.0 + 1.0j, -3.0 - 1.0j])
    K = codyna.place(A, B, poles)
    assert K.shape == (1, 4)
    got = np.sort_complex(np.linalg.eigvals(A - B @ K))
    assert np.allclose(got, np.sort_complex(poles), rtol=1e-8, atol=1e-8), got


# ---------------------------------------------------------------------------- the example

def test_example_script_writes_its_png(tmp_path):
    script = os.path.join(SOURCE_DIR, "examples", "python", "cart_pendulum_lqr.py")
    png = tmp_path / "cart_pendulum_lqr.png"
    p = subprocess.run([sys.executable, script, str(png)], capture_output=True, text=True, cwd=tmp_path,
                       env=dict(CHILD_ENV, MPLBACKEND="Agg"), timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20000
    assert "K =" in p.stdout and "closed-loop poles" in p.stdout and "max |y - y_lin|" in p.stdout, p.stdout


# ---------------------------------------------------------------------------- sweep

ROD_MASS = "/bodies/1/mass"


def sorted_poles(p):
    p = np.asarray(p)
    return p[np.lexsort((p.imag, p.real))]


def cart_with(**masses):
    """The cart-pendulum's JSON text with body masses replaced (index -> kg)."""
    model = json.load(open(CART))
    for index, mass in masses.items():
        model["bodies"][int(index[1:])]["mass"] = mass
    return json.dumps(model)


def test_sweep_rod_mass_fixed_lqr_against_each_variants_own_linearization():
    study = codyna.Study(CART)
    sweep = study.sweep(vary={ROD_MASS: "5:15:11"})
    assert isinstance(sweep, codyna.Sweep) and len(sweep) == 11
    assert sweep.fields == [ROD_MASS] and sweep.specs == ["5:15:11"] and sweep.design == "grid" and sweep.seed is None
    assert np.array_equal(sweep.values[:, 0], np.linspace(5, 15, 11)) and sweep.nominal.tolist() == [10.0]
    assert sweep.status.tolist() == [0] * 11 and sweep.reasons == [""] * 11 and sweep.failed == 0
    assert sweep.closed_loop and not sweep.redesigned and not sweep.simulated
    assert sweep.state_names == ["cart_slider", "rod_pivot", "cart_slider_dot", "rod_pivot_dot"]
    assert sweep.input_names == ["force"] and sweep.output_names == ["h", "theta"]
    assert sweep.A.shape == (11, 4, 4) and sweep.B.shape == (11, 4, 1) and sweep.C.shape == (11, 2, 4)
    assert sweep.D.shape == (11, 2, 1) and sweep.closed_poles.shape == (11, 4) and sweep.closed_poles.dtype == complex
    # K: the model file's LQR (Q = diag(10, 100, 1, 1), R = 0.01) designed once, on the nominal model, by scipy
    nominal = study.linearize()
    X = scipy.linalg.solve_continuous_are(nominal.A, nominal.B, np.diag([10.0, 100.0, 1.0, 1.0]), np.array([[0.01]]))
    K = np.linalg.solve([[0.01]], nominal.B.T @ X)
    assert sweep.K.shape == (1, 4) and np.abs(sweep.K - K).max() <= 1e-9 * np.abs(K).max()
    base = os.path.join(SOURCE_DIR, "examples")
    for i, mass in enumerate(sweep.values[:, 0]):
        # the variant's own model: the JSON edited here, linearized by Study.linearize
        lin = codyna.Study.from_json(cart_with(b1=mass), base_dir=base).linearize()
        assert np.array_equal(sweep.A[i], lin.A) and np.array_equal(sweep.B[i], lin.B), i
        assert np.array_equal(sweep.C[i], lin.C) and np.array_equal(sweep.D[i], lin.D), i
        expected = sorted_poles(np.linalg.eigvals(lin.A - lin.B @ sweep.K))
        assert np.abs(sweep.closed_poles[i] - expected).max() < 1e-10, (i, sweep.closed_poles[i], expected)
        assert np.abs(sweep.open_poles[i] - sorted_poles(np.linalg.eigvals(lin.A))).max() < 1e-10, i
        assert sweep.closed_max_real[i] == sweep.closed_poles[i].real.max() and sweep.open_max_real[i] == sweep.open_poles[i].real.max()
        if i == 0:  # K is the nominal one: a gain designed on the 5 kg variant would put the poles elsewhere
            Xi = scipy.linalg.solve_continuous_are(lin.A, lin.B, np.diag([10.0, 100.0, 1.0, 1.0]), np.array([[0.01]]))
            redesigned = sorted_poles(np.linalg.eigvals(lin.A - lin.B @ (100.0 * lin.B.T @ Xi)))
            assert np.abs(sweep.closed_poles[0] - redesigned).max() > 1e-3
    assert sweep.stable.dtype == bool and sweep.stable.all() and sweep.stable_count == 11
    # the summary's worst case: the 5 kg rod, max Re = -0.6175065646 (docs/parameter-studies.md)
    assert sweep.worst == 0 and abs(sweep.closed_max_real[0] - (-0.6175065646)) < 1e-10
    assert int(np.argmax(sweep.closed_max_real)) == sweep.worst
    assert "worst case       variant 0: /bodies/1/mass = 5, max Re(closed-loop pole) = -0.6175065646" in sweep.summary
    assert sweep.written == () and sweep.sim_status is None and sweep.overshoot is None
    # the same study from the JSON text, and with the values given as a numpy array
    text = codyna.Study.from_json(open(CART).read(), base_dir=base).sweep(vary={ROD_MASS: np.linspace(5, 15, 11)})
    assert text.model_file == os.path.join(base, "<json>") and text.specs[0].startswith("[5,6,7,")
    for key in ("values", "A", "B", "C", "D", "open_poles", "closed_poles", "K"):
        assert np.array_equal(getattr(text, key), getattr(sweep, key)), key


# dataset -> Sweep attribute (every dataset of the file is one of these)
SWEEP_DATASETS = {
    "parameters/values": "values", "parameters/fields": "fields", "parameters/specs": "specs",
    "parameters/nominal": "nominal", "status/code": "status", "status/reason": "reasons",
    "names/states": "state_names", "names/inputs": "input_names", "names/outputs": "output_names",
    "linear/A": "A", "linear/B": "B", "linear/C": "C", "linear/D": "D",
    "open_loop/max_real": "open_max_real", "open_loop/uncontrollable": "uncontrollable",
    "open_loop/stable": "stable", "closed_loop/K": "K", "closed_loop/max_real": "closed_max_real",
    "closed_loop/stable": "stable", "simulation/status": "sim_status", "simulation/reason": "sim_reason",
    "simulation/t_reached": "t_reached", "simulation/peak_input": "peak_input",
    "simulation/final_error": "final_error", "simulation/overshoot": "overshoot",
    "simulation/settling_time": "settling_time", "simulation/saturation_time": "saturation_time",
}


def check_sweep_against_h5(sweep, path):
    """Every dataset and root attribute of a codyna sweep HDF5 file against the Sweep, exactly."""
    checked = set()
    with h5py.File(path, "r") as f:
        datasets = {}
        f.visititems(lambda name, obj: datasets.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        for group in ("open_loop", "closed_loop"):
            if group + "/poles_real" in datasets:
                poles = datasets.pop(group + "/poles_real") + 1j * datasets.pop(group + "/poles_imag")
                got = getattr(sweep, group.replace("_loop", "") + "_poles")
                assert got.shape == poles.shape and np.array_equal(got, poles, equal_nan=True), group
                checked.add(group + "/poles")
        for name, data in datasets.items():
            assert name in SWEEP_DATASETS, "a dataset the test does not know: " + name
            got = getattr(sweep, SWEEP_DATASETS[name])
            if data.dtype.kind in "OS":
                assert list(got) == [x.decode() for x in data], name
            else:
                got = np.asarray(got)
                assert got.shape == data.shape and np.array_equal(got, data, equal_nan=True), name
            checked.add(name)
        attrs = dict(f.attrs)
        for key in ("design", "operating_point", "method", "controller", "model_name", "model_file"):
            value = attrs[key].decode() if isinstance(attrs[key], bytes) else str(attrs[key])
            assert value == str(getattr(sweep, key)), key
        assert attrs["variants"] == len(sweep)
        assert attrs.get("seed") == sweep.seed
        gain = attrs["gain"].decode() if isinstance(attrs["gain"], bytes) else str(attrs["gain"])
        assert gain == ("none" if not sweep.closed_loop else "redesigned" if sweep.redesigned else "fixed")
    return checked


def test_sweep_monte_carlo_equals_the_cli_and_itself(tmp_path):
    vary = ["/bodies/1/mass=normal(10,3)", "/bodies/0/mass=uniform(10,30)"]
    stdout, _ = cli("sweep", CART, *sum((["--vary", v] for v in vary), []), "--samples", 100, "--seed", 7, "--simulate",
                    "--out", tmp_path / "cli.h5", "--csv", tmp_path / "cli.csv", "--mat", tmp_path / "cli" / "mc.mat", "--quiet")
    study = codyna.Study(CART)
    a = study.sweep(vary, samples=100, seed=7, simulate=True, threads=1, out=tmp_path / "py.h5", csv=str(tmp_path / "py.csv"),
                    mat=tmp_path / "py" / "mc.mat")
    b = study.sweep(vary={f: s for f, s in (v.split("=", 1) for v in vary)}, samples=100, seed=7, simulate=True, threads=2)
    assert a.design == "random" and a.seed == 7 and len(a) == 100 and a.simulated
    assert a.written == tuple(str(tmp_path / f) for f in ("py.h5", "py.csv", "py/mc.mat", "py/mc.m"))
    # the command line's file, dataset by dataset: every one checked
    checked = check_sweep_against_h5(a, tmp_path / "cli.h5")
    # parameters 4, status 2, names 3, linear 4, open_loop 3 (poles, max_real, uncontrollable),
    # closed_loop 4 (K, poles, max_real, stable), simulation 8
    assert len(checked) == 28, sorted(checked)
    # the same study twice (1 and 2 threads): the same numbers
    for key in ("values", "status", "A", "B", "C", "D", "open_poles", "closed_poles", "stable", "peak_input",
                "final_error", "overshoot", "settling_time", "saturation_time", "t_reached", "sim_status"):
        assert np.array_equal(getattr(a, key), getattr(b, key), equal_nan=True), key
    assert a.summary == b.summary
    # what the command prints, and the files the module's call wrote: the command's bytes
    assert stdout.startswith(a.summary), stdout
    assert (tmp_path / "py.h5").read_bytes() == (tmp_path / "cli.h5").read_bytes()
    assert (tmp_path / "py.csv").read_text() == (tmp_path / "cli.csv").read_text()
    for f in ("mc.mat", "mc.m"):
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f
    assert a.peak_input.shape == (100, 1) and a.overshoot.shape == (100, 2) and a.saturation_time.shape == (100, 1)
    assert a.largest_input is not None and a.peak_input[a.largest_input, 0] == np.nanmax(a.peak_input)


def test_sweep_failed_variants_are_recorded():
    study = codyna.Study(CART)
    nominal = study.linearize()
    sweep = study.sweep(vary={ROD_MASS: [0, -1, 10]}, redesign="lqr")
    assert sweep.specs == ["[0,-1,10]"] and sweep.redesigned
    # a massless rod: nothing can move its angle, so no LQR; a negative mass: the model is refused
    assert sweep.status.tolist() == [3, 1, 0]
    assert sweep.status_text == ["refused", "model error", "ok"]
    assert "lqr: the plant is not stabilizable" in sweep.reasons[0], sweep.reasons[0]
    assert sweep.reasons[1] == CART + ": /bodies/1/mass: expected a non-negative mass (kg), got number -1.0"
    assert sweep.reasons[2] == "" and sweep.failed == 2 and sweep.worst == 2
    for i in (0, 1):
        assert np.isnan(sweep.A[i]).all() and np.isnan(sweep.K[i]).all() and np.isnan(sweep.closed_poles[i].real).all()
        assert np.isnan(sweep.closed_max_real[i]) and sweep.uncontrollable[i] == -1 and not sweep.stable[i]
    assert np.array_equal(sweep.A[2], nominal.A) and np.array_equal(sweep.B[2], nominal.B)
    # the 10 kg variant's LQR designed again is the nominal one (the fixed K of the study without redesign)
    fixed = study.sweep(vary={ROD_MASS: [0, 10]})
    assert np.abs(sweep.K[2] - fixed.K).max() <= 1e-12 * np.abs(fixed.K).max()
    # without redesign the massless rod completes: unstable, one mode the force cannot move
    assert fixed.status.tolist() == [0, 0] and fixed.uncontrollable.tolist() == [1, 0]
    assert fixed.stable.tolist() == [False, True] and fixed.worst == 0
    assert "failed           variant 0 (refused): " + sweep.reasons[0] + "\n" in sweep.summary
    assert "                 variant 1 (model error): " + sweep.reasons[1] + "\n" in sweep.summary


def test_sweep_bad_keywords():
    study = codyna.Study(CART)
    with pytest.raises(ValueError, match="^vary /bodies/1/masse=1:2:3: .*has no field /bodies/1/masse"):
        study.sweep(vary="/bodies/1/masse=1:2:3")
    with pytest.raises(ValueError, match="^vary /bodies/1/name=.*/bodies/1/name"):
        study.sweep(vary={"/bodies/1/name": [1, 2]})
    with pytest.raises(ValueError, match="^vary: give at least one FIELD=SPEC"):
        study.sweep()
    with pytest.raises(ValueError, match="^vary: a grid .* cannot be mixed"):
        study.sweep(vary={ROD_MASS: "normal(10,3)", "/bodies/0/mass": "10:30:3"}, samples=5, seed=1)
    with pytest.raises(ValueError, match="^seed: a random study"):
        study.sweep(vary={ROD_MASS: "normal(10,3)"}, samples=5)
    with pytest.raises(ValueError, match="^samples: a grid study"):
        study.sweep(vary={ROD_MASS: "5:15:3"}, samples=5)
    with pytest.raises(ValueError, match="^redesign lqrr: expected lqr"):
        study.sweep(vary={ROD_MASS: "5:15:3"}, redesign="lqrr")
    with pytest.raises(ValueError, match="^seed: expected a whole number from 0"):
        study.sweep(vary={ROD_MASS: "normal(10,3)"}, samples=5, seed=-1)
    with pytest.raises(ValueError, match="contradict"):
        study.sweep(vary={ROD_MASS: "5:15:3"}, restart=True, resume=True)
    with pytest.raises(TypeError, match="unexpected keyword argument 'samlpes'"):
        study.sweep(vary={ROD_MASS: "5:15:3"}, samlpes=5)
    with pytest.raises(TypeError, match="samples: expected a whole number"):
        study.sweep(vary={ROD_MASS: "normal(10,3)"}, samples=5.0, seed=1)
    with pytest.raises(TypeError, match=r"vary\[/bodies/1/mass\]: expected a number, got str"):
        study.sweep(vary={ROD_MASS: ["5", "6"]})
    with pytest.raises(TypeError, match="progress: expected a callable"):
        study.sweep(vary={ROD_MASS: "5:15:3"}, progress=3)
    # an output that would replace the model
    with pytest.raises(ValueError, match="cart_pendulum.json"):
        study.sweep(vary={ROD_MASS: "5:15:3"}, out=CART)


def test_sweep_progress_on_the_calling_thread():
    import threading
    calls = []
    sweep = codyna.Study(CART).sweep(vary={ROD_MASS: "5:15:11"}, threads=2,
                                     progress=lambda done, total: calls.append((done, total, threading.get_ident())))
    assert calls and calls[-1][:2] == (11, 11) and len(sweep) == 11
    assert all(c[2] == threading.get_ident() for c in calls)
    assert [c[0] for c in calls] == sorted(c[0] for c in calls)


def test_sweep_stopped_by_its_callback_resumes_from_the_journal(tmp_path):
    study = codyna.Study(CART)
    options = dict(vary={ROD_MASS: "normal(10,3)"}, samples=200, seed=3, simulate=True, threads=1)

    def stop(done, total):
        raise RuntimeError("stop at %d of %d" % (done, total))

    with pytest.raises(RuntimeError, match="^stop at"):
        study.sweep(out=tmp_path / "a.h5", progress=stop, **options)
    journal = tmp_path / "a.h5.partial"
    assert not (tmp_path / "a.h5").exists() and journal.exists()
    kept = len(journal.read_text().splitlines()) - 2  # the head and request lines, then a line per variant
    assert 0 < kept < 200, kept
    resumed = study.sweep(out=tmp_path / "a.h5", **options)
    assert resumed.resumed == kept and not journal.exists()
    assert any(n.startswith("resuming: %d of 200 variants were done" % kept) for n in resumed.notes), resumed.notes
    whole = study.sweep(out=tmp_path / "b.h5", **options)
    assert whole.resumed == 0
    assert (tmp_path / "a.h5").read_bytes() == (tmp_path / "b.h5").read_bytes()


def test_ctrl_c_interrupts_a_sweep(tmp_path):
    # 20000 simulated variants on 2 worker threads (about 40 s), interrupted after a second
    child = r"""
import sys, time, codyna
study = codyna.Study(sys.argv[1])
started = []
def progress(done, total):  # "start" once variants are done (and in the journal)
    if not started:
        started.append(time.monotonic())
        print("start", flush=True)
try:
    study.sweep(vary={"/bodies/1/mass": "normal(10,3)"}, samples=20000, seed=1, simulate=True, threads=2, out=sys.argv[2],
                progress=progress)
    print("completed")
except KeyboardInterrupt:
    print("interrupted after %.3f s" % (time.monotonic() - started[0]), flush=True)
"""
    out = tmp_path / "mc.h5"
    interrupt_a_second_in(child, CART, str(out))
    # the variants done are in the journal, the results file is not written
    done = len((tmp_path / "mc.h5.partial").read_text().splitlines()) - 2
    assert 0 < done < 20000 and not out.exists(), done


# ------------------------------------------------------------------------- shards (Slurm) and their merge

SHARD_GRID = {ROD_MASS: "5:15:6"}


def test_sweep_shards_merged_from_python_equal_the_whole_study_and_the_cli(tmp_path):
    study = codyna.Study(CART)
    whole = study.sweep(vary=SHARD_GRID, threads=1, out=tmp_path / "whole.h5", csv=tmp_path / "whole.csv")
    s0 = study.sweep(vary=SHARD_GRID, shard=(0, 2), threads=1, out=tmp_path / "py0.sweep")
    calls = []
    s1 = study.sweep(vary=SHARD_GRID, shard="1/2", threads=1, out=tmp_path / "py1.sweep",  # the command's spelling
                     progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1] == (3, 3) and all(total == 3 for _, total in calls), calls  # the shard's variants
    # a shard's Sweep: its own variants only (i % 2 == K), the whole study's numbers bit for bit
    assert len(whole) == 6 and whole.shard is None and whole.indices.tolist() == list(range(6))
    assert s0.shard == (0, 2) and s1.shard == (1, 2)
    for part, k in ((s0, 0), (s1, 1)):
        assert len(part) == 3 and part.indices.tolist() == [k, k + 2, k + 4]
        for key in ("values", "status", "A", "B", "C", "D", "open_poles", "closed_poles", "closed_max_real", "stable", "K"):
            expected = getattr(whole, key) if key == "K" else getattr(whole, key)[k::2]
            assert np.array_equal(getattr(part, key), expected), (k, key)
        assert part.failed == 0 and part.stable_count == 3
        assert part.written == (str(tmp_path / ("py%d.sweep" % k)),) and not (tmp_path / ("py%d.sweep.partial" % k)).exists()
        assert part.summary == "shard            %d/2: 3 of the 6 variants (i %% 2 = %d), 0 failed; codyna sweep-merge joins the shards\n" % (k, k)
    # worst: a row of the shard's arrays; its number in the study is indices[worst] (the 5 kg rod, variant 0)
    assert whole.worst == 0 and s0.worst == 0 and s0.indices[s0.worst] == 0
    assert s1.worst == 0 and s1.indices[s1.worst] == 1 and s1.closed_max_real[0] == s1.closed_max_real.max()
    # the merge (shards in another order): the whole study's files byte for byte, its Sweep
    merged = codyna.sweep_merge([tmp_path / "py1.sweep", str(tmp_path / "py0.sweep")], out=tmp_path / "merged.h5",
                                csv=tmp_path / "merged.csv")
    assert (tmp_path / "merged.h5").read_bytes() == (tmp_path / "whole.h5").read_bytes()
    assert (tmp_path / "merged.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()
    assert not (tmp_path / "merged.h5.partial").exists() and (tmp_path / "py0.sweep").exists()
    assert isinstance(merged, codyna.Sweep) and len(merged) == 6 and merged.shard is None
    assert merged.written == (str(tmp_path / "merged.h5"), str(tmp_path / "merged.csv"))
    assert merged.summary == whole.summary and merged.worst == 0 and merged.notes == whole.notes
    for key in ("values", "status", "A", "B", "C", "D", "open_poles", "closed_poles", "stable", "K", "indices"):
        assert np.array_equal(getattr(merged, key), getattr(whole, key)), key
    # the command line: its shards are the module's bytes, its merge the same file
    for k in (0, 1):
        stdout, _ = cli("sweep", CART, "--vary", ROD_MASS + "=5:15:6", "--shard", "%d/2" % k, "--threads", 1,
                        "--out", tmp_path / ("cli%d.sweep" % k), "--quiet")
        assert stdout.startswith(s0.summary if k == 0 else s1.summary), stdout
        assert (tmp_path / ("cli%d.sweep" % k)).read_bytes() == (tmp_path / ("py%d.sweep" % k)).read_bytes(), k
    cli("sweep-merge", tmp_path / "cli0.sweep", tmp_path / "cli1.sweep", "--out", tmp_path / "cli.h5")
    assert (tmp_path / "cli.h5").read_bytes() == (tmp_path / "merged.h5").read_bytes()


def test_sweep_merge_refusals_are_the_clis(tmp_path):
    study = codyna.Study(CART)
    study.sweep(vary=SHARD_GRID, shard=(0, 2), threads=1, out=tmp_path / "s0.sweep")
    study.sweep(vary={ROD_MASS: "5:15:4"}, shard=(1, 2), threads=1, out=tmp_path / "other.sweep")  # another study

    def refused(shards, out):
        _, stderr = cli("sweep-merge", *shards, "--out", out, expect=1)
        with pytest.raises(ValueError) as e:
            codyna.sweep_merge(shards, out=out)
        assert "codyna: error: " + str(e.value) + "\n" == stderr
        assert not os.path.exists(out) and not os.path.exists(str(out) + ".partial")
        return str(e.value)

    # a shard missing: the variants no shard holds are named
    assert refused([tmp_path / "s0.sweep"], tmp_path / "half.h5") == (
        "sweep-merge: variants 1, 3, 5 (3 of 6) are in none of the shards given: run (or resume) their shards first")
    assert refused([tmp_path / "s0.sweep", tmp_path / "other.sweep"], tmp_path / "mixed.h5") == (
        str(tmp_path / "other.sweep") + ": a shard of another study than " + str(tmp_path / "s0.sweep") +
        " (other model file contents or options)")
    (tmp_path / "notes.txt").write_text("not a shard\n")
    assert refused([tmp_path / "notes.txt"], tmp_path / "x.h5") == str(tmp_path / "notes.txt") + ": not a shard written by codyna sweep --shard"
    with pytest.raises(TypeError, match="shards: expected a list of paths"):
        codyna.sweep_merge([3], out=tmp_path / "x.h5")
    with pytest.raises(TypeError, match="missing 1 required keyword-only argument: 'out'"):
        codyna.sweep_merge([tmp_path / "s0.sweep"])


@pytest.mark.parametrize("shard", [(2, 2), (-1, 2), (0, 0), (1, -3), "2/2", "1/0", "-1/2", "1 /2", "0/2/3", "a/b", (0, 1, 2), ()])
def test_sweep_bad_shard_values(shard, tmp_path):
    with pytest.raises(ValueError) as e:
        codyna.Study(CART).sweep(vary=SHARD_GRID, shard=shard, out=tmp_path / "s.sweep")
    assert str(e.value) == ('shard: expected (K, N), "K/N" or "slurm" with N >= 1 and 0 <= K < N (K counts from 0, as '
                            "codyna sweep --shard K/N), got " + repr(shard))
    assert not (tmp_path / "s.sweep").exists()


SLURM_VARIABLES = ("SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_ARRAY_TASK_MIN")


def slurm_array(monkeypatch, task_id=None, count=None, first=None):
    """Sets (None: removes) the Slurm job array's variables; monkeypatch restores os.environ after the test."""
    for name, value in zip(SLURM_VARIABLES, (task_id, count, first)):
        if value is None:
            monkeypatch.delenv(name, raising=False)
        else:
            monkeypatch.setenv(name, value)


def test_sweep_shard_slurm_is_the_array_tasks_shard(tmp_path, monkeypatch):
    study = codyna.Study(CART)
    by_hand = study.sweep(vary=SHARD_GRID, shard=(1, 2), threads=1, out=tmp_path / "hand.sweep")
    # an array --array=0-1, task 1 (the command's --shard slurm: the same reader, core/study/sweep_shard.cpp)
    slurm_array(monkeypatch, "1", "2", "0")
    task = study.sweep(vary=SHARD_GRID, shard="slurm", threads=1, out=tmp_path / "slurm.sweep")
    assert task.shard == (1, 2) and task.indices.tolist() == [1, 3, 5]
    assert (tmp_path / "slurm.sweep").read_bytes() == (tmp_path / "hand.sweep").read_bytes()
    assert np.array_equal(task.closed_poles, by_hand.closed_poles)
    stdout, _ = cli("sweep", CART, "--vary", ROD_MASS + "=5:15:6", "--shard", "slurm", "--threads", 1,
                    "--out", tmp_path / "cli.sweep", "--quiet")  # the child inherits the variables
    assert stdout.startswith(by_hand.summary), stdout
    assert (tmp_path / "cli.sweep").read_bytes() == (tmp_path / "hand.sweep").read_bytes()
    # an array --array=1-2 counts its IDs from SLURM_ARRAY_TASK_MIN: task 2 is shard 1 of 2 too
    slurm_array(monkeypatch, "2", "2", "1")
    again = study.sweep(vary=SHARD_GRID, shard="slurm", threads=1, out=tmp_path / "from_one.sweep")
    assert again.shard == (1, 2)
    assert (tmp_path / "from_one.sweep").read_bytes() == (tmp_path / "hand.sweep").read_bytes()
    # no MIN: IDs from 0
    slurm_array(monkeypatch, "0", "2")
    assert study.sweep(vary=SHARD_GRID, shard="slurm", threads=1, out=tmp_path / "zero.sweep").shard == (0, 2)


@pytest.mark.parametrize("task_id, count, first, message", [
    (None, None, None, "SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT are not set (not in a Slurm job array)"),
    ("1", None, "0", "SLURM_ARRAY_TASK_COUNT is not set (not in a Slurm job array)"),
    (None, "2", None, "SLURM_ARRAY_TASK_ID is not set (not in a Slurm job array)"),
    ("one", "2", None, "SLURM_ARRAY_TASK_ID=one: expected a whole number (0 or more)"),
    ("1", "2", "", "SLURM_ARRAY_TASK_MIN=: expected a whole number (0 or more)"),
    ("12", "4", "0", "SLURM_ARRAY_TASK_ID=12 - SLURM_ARRAY_TASK_MIN=0 is not a shard of SLURM_ARRAY_TASK_COUNT=4: expected "
                     "0 <= ID - MIN < COUNT (an array of consecutive tasks, e.g. --array=0-15, with no step or gaps)"),
])
def test_sweep_shard_slurm_refusals_name_the_variables(task_id, count, first, message, tmp_path, monkeypatch):
    slurm_array(monkeypatch, task_id, count, first)
    with pytest.raises(ValueError) as e:
        codyna.Study(CART).sweep(vary=SHARD_GRID, shard="slurm", out=tmp_path / "s.sweep")
    assert str(e.value) == "shard='slurm': " + message
    # the command refuses the same, naming its option
    _, stderr = cli("sweep", CART, "--vary", ROD_MASS + "=5:15:6", "--shard", "slurm", "--out", tmp_path / "s.sweep", expect=1)
    assert stderr == "codyna: error: --shard slurm: " + message + "\n"
    assert os.listdir(tmp_path) == []


def test_sweep_shard_refusals(tmp_path):
    study = codyna.Study(CART)
    with pytest.raises(TypeError, match=r"^sweep\(\): shard: expected a whole number \(int\), got float$"):
        study.sweep(vary=SHARD_GRID, shard=(0.0, 2), out=tmp_path / "s.sweep")
    with pytest.raises(TypeError, match=r'^sweep\(\): shard: expected a tuple \(K, N\), a "K/N" str or "slurm", got int$'):
        study.sweep(vary=SHARD_GRID, shard=1, out=tmp_path / "s.sweep")
    # the core's refusals, as the command's (the keyword named as Python writes it)
    with pytest.raises(ValueError, match=r"^shard: give out \(the shard's file\)$"):
        study.sweep(vary=SHARD_GRID, shard=(0, 2))
    with pytest.raises(ValueError, match="^shard: a shard writes its variants only"):
        study.sweep(vary=SHARD_GRID, shard=(0, 2), out=tmp_path / "s.sweep", csv=tmp_path / "s.csv")
    with pytest.raises(ValueError, match="^shard: a Study.from_json has no model file for sweep_merge"):
        codyna.Study.from_json(open(CART).read()).sweep(vary=SHARD_GRID, shard=(0, 2), out=tmp_path / "s.sweep")
    assert os.listdir(tmp_path) == []


def test_a_steady_turn_and_its_handling_numbers_as_the_command_gives_them(tmp_path):
    # the single-track car (Rajamani's bicycle) at its steady motion straight at 30 m/s: the
    # handling numbers equal the closed forms (K = m/L (b/Cf - a/Cr), U_ch = sqrt(L/K)) and the
    # command's NAME.mat struct `handling` to the bit; a steady turn of 120 m (steer and drive
    # solved) holds r R = V and linearizes about the motion
    car = os.path.join(os.path.dirname(CART), "single_track_car.json")
    lin = codyna.Study(car).linearize()
    assert lin.operating_point["kind"] == "steady"
    m, L, a, b, C = 1573.0, 2.68, 1.1, 1.58, 160000.0
    K = m / L * (b / C - a / C)
    h = lin.handling
    assert abs(h["understeer_gradient"] - K) <= 1e-10 * K
    assert abs(h["characteristic_speed"] - (L / K) ** 0.5) <= 1e-10 * (L / K) ** 0.5
    cli("linearize", car, "--out", tmp_path)
    import scipy.io
    mat = scipy.io.loadmat(tmp_path / "single_track_car.mat", squeeze_me=True)
    for key, value in h.items():
        assert float(mat["handling"][key]) == value, key
    turn = codyna.Study(car).linearize(radius=120.0, free_input=["steer", "drive"])
    r = turn.handling
    assert r["speed"] == pytest.approx(30.0, rel=1e-9)
    assert any("linearized about the motion" in n for n in turn.notes), turn.notes
    with pytest.raises(codyna.ModelError, match="radius"):
        codyna.Study(car).linearize(radius=0.0)


def test_the_integrators_are_the_cores_one_list():
    """simulate()'s docstring and its refusal of an unknown integrator name the core's list, which
    the command line's help shows too (one list: core/model/model_spec.hpp's kIntegratorNames)."""
    names = codyna.integrators
    assert names[0] == "auto" and len(names) >= 6
    doc = codyna.Study.simulate.__doc__
    assert "@INTEGRATORS@" not in doc
    line = next(l for l in doc.splitlines() if l.strip().startswith("integrator "))
    assert line.split(":", 1)[1].strip() == ", ".join(f'"{n}"' for n in names)
    help_text, _ = cli("simulate", "--help")
    assert " | ".join(names) in help_text
    with pytest.raises(ValueError) as e:
        codyna.Study(CART).simulate(integrator="euler", t_end=0.1)
    assert "euler" in str(e.value)
    for n in names[1:]:
        assert n in str(e.value)


def test_alf_settings_are_the_command_lines(tmp_path):
    """alf's settings as keywords: the same run as codyna simulate's flags (fixed steps of 5 ms over
    1 s: 200 steps, the same samples); a bad value names its keyword."""
    held = os.path.join(SOURCE_DIR, "examples", "four_bar_held.json")
    r = codyna.Study(held).simulate(integrator="alf", alf_fixed_step=True, max_step=0.005, alf_penalty=1e10,
                                    alf_iterations=50, t_end=1.0)
    assert r.completed
    stdout, _ = cli("simulate", held, "--out", tmp_path / "alf.h5", "--quiet", "--integrator", "alf", "--alf-fixed-step",
                    "--max-step", "0.005", "--alf-penalty", "1e10", "--alf-iterations", "50", "--t-end", "1")
    assert "alf (fixed steps of 0.005 s, penalty 1e+10, at most 50 iterations a step" in stdout
    assert ": 200 steps" in stdout
    end = float(next(l for l in stdout.splitlines() if l.startswith("output rocker_angle")).split()[5])
    assert abs(r.y[-1, 0] - end) < 1e-5 * abs(end)
    # extrapolated: three trapezoidal steps a 5 ms step, the same end by keyword and by flag
    x = codyna.Study(held).simulate(integrator="alf", alf_fixed_step=True, alf_extrapolate=True, max_step=0.005, t_end=1.0)
    assert x.completed
    stdout, _ = cli("simulate", held, "--out", tmp_path / "alfx.h5", "--quiet", "--integrator", "alf", "--alf-fixed-step",
                    "--alf-extrapolate", "--max-step", "0.005", "--t-end", "1")
    assert "alf (fixed steps of 0.005 s, each step extrapolated from two halves, penalty 1e+11" in stdout
    assert ": 600 steps" in stdout
    end = float(next(l for l in stdout.splitlines() if l.startswith("output rocker_angle")).split()[5])
    assert abs(x.y[-1, 0] - end) < 1e-5 * abs(end)
    # extrapolated under error control: runs, and lands where the fixed-step run did
    xe = codyna.Study(held).simulate(integrator="alf", alf_extrapolate=True, t_end=1.0)
    assert xe.completed
    assert abs(xe.y[-1, 0] - end) < 1e-3 * abs(end)
    with pytest.raises(ValueError) as e:
        codyna.Study(held).simulate(integrator="alf", alf_penalty=-1.0, t_end=0.1)
    assert "alf_penalty" in str(e.value)
    with pytest.raises(ValueError) as e:
        codyna.Study(held).simulate(integrator="alf", alf_iterations=0, t_end=0.1)
    assert "alf_iterations" in str(e.value)


def test_maneuver_is_the_command_lines():
    """Study.maneuver runs codyna maneuver's job: the same report text; bad keywords name themselves."""
    car = os.path.join(SOURCE_DIR, "examples", "single_track_car.json")
    stdout, _ = cli("maneuver", car, "--type", "step-steer", "--steer", "0.001")
    r = codyna.Study(car).maneuver("step-steer", steer=0.001)
    assert r["text"] == stdout
    assert r["valid"] and abs(r["yaw_rate"]["gain"] - 7.03443) < 1e-3 * 7.03443
    assert r["output_names"] == ["yaw_rate", "lateral_velocity", "lateral_acceleration"]
    assert len(r["t"]) == r["outputs"].shape[0]
    cr = codyna.Study(car).maneuver("constant-radius", radius=120, speed_min=10, speed_max=30, points=3,
                                    free_inputs=["steer", "drive"])
    assert list(cr["speed"]) == [10, 20, 30]
    with pytest.raises(ValueError, match="^preview: expected a number > 0"):
        codyna.Study(os.path.join(SOURCE_DIR, "tests", "data", "single_track_car_driver.json")).maneuver(
            "double-lane-change", preview=-1)
    # the lane change: its lane and cones as arrays; ISO 3888-1's section 1 cones (15 m from 50 m)
    # stand (1.1 w + 0.25) / 2 either side of the start's line (w = 1.8 m)
    driver = os.path.join(SOURCE_DIR, "tests", "data", "single_track_car_driver.json")
    dlc = codyna.Study(driver).maneuver("double-lane-change", speed=16.7)
    assert dlc["lane_path"].shape[1] == 2 and dlc["lane_path"].shape[0] > 10
    first = [c for c in dlc["lane_cones"] if 50 - 1e-9 <= c[0] <= 65 + 1e-9]
    assert len(first) >= 4
    assert all(abs(abs(c[1]) - (1.1 * 1.8 + 0.25) / 2) < 1e-9 for c in first)
    assert len(dlc["cones_hit"]) == 1 and dlc["cones_hit"][0].startswith("section 5")
    # the hit section's clearance is the one below zero
    assert dlc["cone_clearance"].shape == (3,) and dlc["cone_clearance"][2] < 0 < min(dlc["cone_clearance"][:2])
    # the model file's yaw-moment controller beside the driver: its input and effort, and the
    # outputs the driver read (the file's Plant/Out is the yaw rate alone)
    ym = codyna.Study(os.path.join(SOURCE_DIR, "tests", "data", "single_track_car_yaw_moment.json"))
    both = ym.maneuver("double-lane-change", speed=22.2, preview=6, drive="drive", speed_kp=2000, speed_ki=500)
    assert both["controller_inputs"] == ["yaw_moment"]
    assert both["controller_effort"][0] == pytest.approx(3495.02, rel=1e-4)
    assert both["output_names"] == ["yaw_rate", "x", "y", "yaw", "speed"]
    assert both["cones_hit"] == [] and both["path_error_max"] == pytest.approx(0.311875, rel=1e-4)
    alone = ym.maneuver("double-lane-change", speed=22.2, preview=6, drive="drive", speed_kp=2000, speed_ki=500,
                        open_loop=True)
    assert "controller" not in alone and alone["path_error_max"] == pytest.approx(0.30201, rel=1e-4)
    with pytest.raises(ValueError, match="^drive: the driver needs the actuator \"throttle\""):
        ym.maneuver("double-lane-change", drive="throttle")
    with pytest.raises(ValueError, match="^dwell_roll_rate: give the dwell or the roll rate that ends it, not both"):
        codyna.Study(car).maneuver("fishhook", dwell=0.2, dwell_roll_rate=1.5)
    with pytest.raises(ValueError, match="^dwell_roll_rate: the step-steer maneuver does not take it"):
        codyna.Study(car).maneuver("step-steer", dwell_roll_rate=1.5)
    with pytest.raises(ValueError, match="^type: unknown maneuver"):
        codyna.Study(car).maneuver("slalom")
    # the swept sine: the command line's text; the responses as complex arrays beside the linear ones
    stdout, _ = cli("maneuver", car, "--type", "swept-sine", "--steer", "0.001", "--points", "5")
    sw = codyna.Study(car).maneuver("swept-sine", steer=0.001, points=5)
    assert sw["text"] == stdout
    assert sw["yaw_rate_response"].dtype == complex and sw["yaw_rate_response"].shape == (5,)
    assert np.max(np.abs(sw["yaw_rate_response"] - sw["yaw_rate_response_linear"])
                  / np.abs(sw["yaw_rate_response_linear"])) < 1e-3
    assert sw["characteristics"]["resonance_hz"] == pytest.approx(sw["characteristics_linear"]["resonance_hz"], rel=1e-3)
    with pytest.raises(ValueError, match="^frequency_max: expected a frequency above frequency_min"):
        codyna.Study(car).maneuver("swept-sine", frequency_max=0.05)
    # the sedan with its yaw-rate controller: a swept sine refuses it, naming the keyword; a step
    # steer runs it (its brakes, its reference) and open_loop=True leaves it out
    esc = codyna.Study(os.path.join(SOURCE_DIR, "examples", "sedan_esc.json"))
    with pytest.raises(ValueError, match="^open_loop: the model file has a pid controller"):
        esc.maneuver("swept-sine")
    with pytest.raises(ValueError, match="^friction: expected a number > 0"):
        esc.maneuver("step-steer", friction=0)
    on = esc.maneuver("step-steer", steer=0.01, t_end=1.2)
    assert on["controller_inputs"] == ["brake_fl", "brake_fr"]
    assert on["reference_limit"] == pytest.approx(0.85 * 9.80665 / 25, rel=1e-6)
    assert 0 < max(on["controller_effort"]) <= 3000
    off = esc.maneuver("step-steer", steer=0.01, t_end=1.2, open_loop=True)
    assert "controller" not in off and off["max_sideslip"] > on["max_sideslip"] > 0


def test_kc_is_the_command_lines(tmp_path):
    """Study.kc runs codyna kc's job: the same text and CSV; a range as (min, max, n) is the same
    as its text; the gradients are numbers of the report; a bad range names the keyword."""
    corner = os.path.join(SOURCE_DIR, "examples", "kc_double_wishbone.json")
    stdout, _ = cli("kc", corner, "--travel=-0.02:0.02:5", "--steer-range=-0.01:0.01:3", "--csv", tmp_path / "cli.csv")
    study = codyna.Study(corner)
    r = study.kc(travel="-0.02:0.02:5", steer_range=(-0.01, 0.01, 3), csv=str(tmp_path / "py.csv"))
    assert r["text"] + "wrote %s\n" % (tmp_path / "cli.csv") == stdout
    assert (tmp_path / "py.csv").read_text() == (tmp_path / "cli.csv").read_text()
    g = r["wheels"][0]["gradients"]
    assert "bump steer" in r["text"] and np.isfinite(g["bump_steer"]) and g["bump_steer"] != 0
    travel = [p for p in r["points"] if p["sweep"] == "travel"]
    assert [p["travel"] for p in travel] == pytest.approx([-0.02, -0.01, 0, 0.01, 0.02], abs=1e-15)
    # bump steer is d(toe)/d(travel) at design: the table's central difference about it
    mid = (travel[3]["toe"] - travel[1]["toe"]) / 0.02
    assert mid == pytest.approx(g["bump_steer"], rel=1e-2)
    with pytest.raises(ValueError, match="travel"):
        study.kc(travel=(0.02, -0.02, 5))


def test_freqresp_is_the_command_lines(tmp_path):
    """Study.freqresp runs codyna freqresp's job: the same text and CSV; G equals the linear
    response at a small amplitude; a bad keyword names itself."""
    car = os.path.join(SOURCE_DIR, "examples", "single_track_car.json")
    stdout, _ = cli("freqresp", car, "--frequencies", "0.5,3,20", "--amplitude", "1e-4", "--csv", tmp_path / "cli.csv")
    r = codyna.Study(car).freqresp([0.5, 3, 20], amplitude=1e-4, csv=str(tmp_path / "py.csv"))
    assert r["text"] + "wrote %s\n" % (tmp_path / "cli.csv") == stdout
    assert (tmp_path / "py.csv").read_text() == (tmp_path / "cli.csv").read_text()
    assert r["G"].shape == (3, 3, 1) and r["G"].dtype == complex
    assert np.max(np.abs(r["G"] - r["G_linear"]) / np.abs(r["G_linear"])) < 3e-5
    assert r["largest_gap"] == pytest.approx(np.max(r["gap"]), rel=1e-15)
    # the HDF5 file holds the same responses (nw x ny x nu), the names and the kind
    h = codyna.Study(car).freqresp([0.5, 3], amplitude=1e-4, out=str(tmp_path / "fr.h5"))
    with h5py.File(tmp_path / "fr.h5", "r") as f:
        assert f.attrs["kind"] == "frequency_response"
        assert np.array_equal(f["w"][()], [0.5, 3])
        assert [n.decode() for n in f["output_names"][()]] == h["output_names"]
        assert np.array_equal(f["G_real"][()] + 1j * f["G_imag"][()], h["G"])
        assert np.array_equal(f["G_linear_real"][()] + 1j * f["G_linear_imag"][()], h["G_linear"])
        assert np.array_equal(f["gap"][()], h["gap"])
    assert r["input_names"] == ["steer"] and r["operating_point"] == "steady"
    with pytest.raises(ValueError, match="^amplitude 0: expected an amplitude other than 0"):
        codyna.Study(car).freqresp([1], amplitude=0)
    with pytest.raises(TypeError):
        codyna.Study(car).freqresp([1], amplitudes=1)
