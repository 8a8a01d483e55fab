"""codyna: multibody dynamics with a control module, from Python.

A thin binding of codyna's core study layer (core/study/): every call below is one call of
the same C++ function `codyna linearize` and `codyna simulate` make, so the numbers are the
command line's, bit for bit. docs/python.md has a tour.

    import codyna
    study = codyna.Study("examples/cart_pendulum.json")
    lin = study.linearize(operating_point="equilibrium")
    lin.A, lin.B, lin.C, lin.D            # numpy float64
    run = study.simulate(lqr=True, t_end=2, compare_linear=True)
    run.t, run.y, run.y_linear
    run.save("run.h5")
    sweep = study.sweep(vary={"/bodies/1/mass": "5:15:11"})   # codyna sweep
    sweep.values, sweep.closed_poles, sweep.stable, sweep.summary
    study.sweep(vary=..., shard=(0, 2), out="s0.sweep")          # codyna sweep --shard 0/2
    study.sweep(vary=..., shard="slurm", out="s.sweep")          # codyna sweep --shard slurm
    codyna.sweep_merge(["s0.sweep", "s1.sweep"], out="study.h5")  # codyna sweep-merge

Errors: a bad model or a bad choice in it raises ModelError (a ValueError) whose message names
the file and the field, as the command line prints it; a bad keyword value raises ValueError
(naming the keyword) or TypeError; an equilibrium or trim that does not converge raises
ConvergenceError (a RuntimeError). Ctrl+C interrupts a simulation or a sweep (KeyboardInterrupt).
"""

from ._codyna import (  # noqa: F401  (the public names)
    ClosedLoop,
    ConvergenceError,
    Linearization,
    ModelError,
    Simulation,
    Sweep,
    __version__,
    integrators,
    lqr,
    place,
)
from . import _codyna

__all__ = [
    "Study",
    "Linearization",
    "ClosedLoop",
    "Simulation",
    "Sweep",
    "ModelError",
    "ConvergenceError",
    "lqr",
    "place",
    "sweep_merge",
    "integrators",
    "__version__",
]


def _given(options):
    """The keywords given (None means: not given, the model file's value stays)."""
    return {k: v for k, v in options.items() if k != "self" and v is not None}


class Study:
    """A model file and its study (the file's "analysis" and "solver" sections).

    Study(path) reads and checks the file (ModelError names the file and the field);
    Study.from_json(text, base_dir=".") does the same for a JSON text. The keywords of
    linearize(), simulate() and sweep() override the file's choices for that one call, as the command
    line's flags do; the file is not changed.
    """

    def __init__(self, path):
        """Reads the model file at `path` (str or os.PathLike)."""
        self._study = _codyna._Study(path)

    @classmethod
    def from_json(cls, text, base_dir="."):
        """A study from a model file's JSON text. Paths in it (a controller file, the export
        folder) are relative to `base_dir`; messages name the text "<json>"."""
        study = cls.__new__(cls)
        study._study = _codyna._Study.from_json(text, base_dir)
        return study

    @property
    def file(self):
        """The model file's path (or the label of a JSON text)."""
        return self._study.file

    @property
    def notes(self):
        """The model reader's notes (list of str): what it read in a way worth saying."""
        return self._study.notes

    def model_info(self):
        """What `codyna info` shows, as a dict: name, file, dof, nq, nv; bodies (name, mass, com,
        joint, parent), joints (name, type, parent, child, coordinates, rates, q_names);
        coordinates with their units, rates, q_names; constraints (name, type, bodies,
        equations), constraint_equations, independent_equations, redundant_equations,
        assembly_residual, assembly_moves; effects; gravity; actuators (name, type, unit, gain,
        u0, min, max) and sensors (name, type, unit), plant_inputs and plant_outputs (names);
        the model's controller type; initial_coordinates and initial_rates by name."""
        return self._study.model_info()

    def to_json(self):
        """The model as the file format writes it (JSON text)."""
        return self._study.to_json()

    def __repr__(self):
        return "codyna.Study(%r)" % self.file

    def linearize(
        self,
        *,
        operating_point=None,
        method=None,
        discrete=None,
        mat_version=None,
        independent=None,
        hold=None,
        initial=None,
        trim_free=None,
        free_input=None,
        free_inputs=None,
        target=None,
        targets=None,
        steady_body=None,
        speed=None,
        yaw_rate=None,
        radius=None,
        lateral_acceleration=None,
        trajectory=None,
        trajectory_step=None,
        name=None,
        closed_loop=None,
        lqr=None,
        controller=None,
        lqr_controllable_part=None,
        q_weights=None,
        r_weights=None,
        inputs=None,
        outputs=None,
        disable_effect=None,
        reference=None,
        disturbance=None,
    ):
        """Linearizes the plant (Plant/In -> Plant/Out) as `codyna linearize` does.

        Returns a Linearization: A, B, C, D (numpy float64), state_names, input_names,
        output_names, x0, u0, y0, xdot0, Ts, operating_point, modes, eigenvalues(), notes,
        warnings, and export(dir), which writes the command line's NAME.mat + NAME.m.

        Every keyword is a flag of `codyna linearize` (dashes become underscores); one left
        out (or None) keeps the model file's choice:

        operating_point   "initial", "equilibrium", "trim", "steady" or "time=T"
        steady_body, speed, yaw_rate, radius, lateral_acceleration   operating point steady:
                          the body whose forward speed (m/s) and turn (one of yaw rate rad/s,
                          path radius m, lateral acceleration m/s^2; > 0 left) are held
                          (docs/vehicles.md); the result's handling gives the handling numbers
                          when the study names its steer input and yaw-rate output
        method            "exact", "fd-forward" or "fd-central"
        discrete          sample time Ts > 0: the exact zero-order-hold model (0: continuous)
        mat_version       "5" or "7.3" (export)
        independent       closed loops: the independent coordinates (list of names)
        hold              {name: value}: coordinates (or rates, NAME_dot) held in the
                          operating-point search (also "NAME=VALUE" strings)
        initial           {name: value}: with trajectory only, the run's initial state
        trim_free         trim: coordinates solved instead of held (list of names)
        free_input        equilibrium/trim: Plant/In inputs solved for (alias free_inputs);
                          steady: any actuator
        target            {output: value}: Plant/Out values the search must reach (alias targets)
        trajectory        T: linearize along a simulation from 0 to T (the model's controller
                          in the loop); A, B, C, D are then stacked along a first axis, one per
                          time (times)
        trajectory_step   spacing of the trajectory's points, s
        name              the export's NAME (a MATLAB identifier)
        closed_loop       True: also the linear closed loop with the study's controller
                          (Linearization.closed_loop: Acl, Bcl, Ccl, Dcl, poles, responses)
        lqr               True: the closed loop's controller is an LQR designed on this plant
        controller        the closed loop's controller from a .mat (K, Kp/Ki/Kd or Ac..Dc)
        lqr_controllable_part  with lqr on a plant that is not stabilizable: design on the
                          controllable part
        q_weights, r_weights   LQR weights (diagonals of Q and R)
        inputs, outputs   Plant/In actuators and Plant/Out sensors for this call (lists of names)
        disable_effect    effects left out (list of names)
        reference         a reference on a Plant/Out: "OUTPUT=VALUE[@TIME]" or a dict as in the
                          file's analysis.references (or a list of them)
        disturbance       a disturbance on an actuator that is not Plant/In: "ACTUATOR=VALUE[@TIME]"
                          or a dict as in the file's analysis.disturbances (or a list of them)

        Raises ModelError (bad model or choice, naming the file and the field), ValueError
        (a bad keyword value, naming the keyword), ConvergenceError (an equilibrium or trim
        that did not converge: nothing is returned), TypeError (an unknown keyword).
        """
        return _codyna._linearize(self._study, _given(locals()))

    def freqresp(self, frequencies, **options):
        """The frequency response of the nonlinear plant against the linear model's (codyna
        freqresp; docs/frequency-response.md).

        frequencies: rad/s (a sequence). Each Plant/In is excited in turn by a sine about the
        operating point, the model run with the study's controller (an unstable plant is measured
        in closed loop), and G(jw) from every Plant/In to every Plant/Out estimated. Keywords:
        amplitude (one number or one per Plant/In, input units; default 0.01), settle_periods,
        periods, samples_per_period, harmonics, csv, out (HDF5), and codyna simulate's point, plant,
        controller and solver keywords (operating_point, hold, speed, radius, lqr, open_loop,
        controller, integrator, rtol, atol, ...). Returns a dict: "w", "G" and "G_linear"
        (complex, frequencies x outputs x inputs), "gap" (|G - G_linear| relative to the linear
        response), "distortion" (the harmonics' share), the names and units, "largest_gap",
        "notes", "warnings" and "text" (the command's report).
        """
        options["frequencies"] = [float(w) for w in frequencies]
        a = options.get("amplitude")
        if a is not None and not hasattr(a, "__len__"):
            options["amplitude"] = [float(a)]
        return _codyna._freqresp(self._study, _given(options))

    def maneuver(self, type, **options):
        """A standard handling maneuver with its metrics (codyna maneuver; docs/maneuvers.md).

        type: "step-steer", "sine-with-dwell", "swept-sine", "double-lane-change",
        "constant-radius" or "constant-speed"; the keywords are codyna maneuver's flags with underscores (speed, steer,
        steer_time, ramp, frequency, dwell, steer_scale, frequency_min, frequency_max, sweep_time, t_end,
        output_step, radius, speed_min, speed_max, ay_min, ay_max, points, width, length, preview, lateral_gain,
        speed_kp, speed_ki, sample_time, x, y, yaw, speed_output, drive, integrator, free_inputs,
        open_loop, friction, out, csv). Returns a dict: the metrics, "valid" and "invalid_reason",
        "text" (the command's report), and the run's "t", "outputs", "output_names". Step steer and
        sine with dwell add "max_sideslip" (rad) and "max_sideslip_time", and with the model file's
        controller in the loop (open_loop=True leaves it out) "controller", "reference_gain",
        "reference_limit", "controller_inputs" and "controller_effort" (largest |u - u0|). The swept sine adds
        "frequency_hz" and the complex responses "yaw_rate_response",
        "lateral_acceleration_response" (and their "..._linear"), "characteristics" (ISO 7401's
        values; "characteristics_linear") and the largest gaps as (gap, Hz).
        """
        options["type"] = type
        return _codyna._maneuver(self._study, _given(options))

    def kc(self, **options):
        """The suspension K&C rig (codyna kc; docs/kc.md): a corner or an axle held at its body,
        swept through wheel travel, roll, steer and contact-patch loads as static equilibria.

        Keywords, as codyna kc's flags with underscores: wheels (one name, or two for an axle; also
        wheel), held, steer, radius, travel, roll, steer_range, fx, fy, mz (each "MIN:MAX:N" or
        (min, max, n)), csv. Returns a dict: "wheels" (each its "name", "radius", "design" point and
        "gradients": bump_steer, bump_camber (deg/m), track_per_travel, roll_centre_height (m),
        roll_steer, roll_camber (deg/deg), fy_/fx_steer and _camber (deg/kN), mz_steer, mz_camber
        (deg/kN m)), "points" (each a dict: sweep, wheel, travel, roll, steer, fx, fy, mz,
        wheel_centre, contact, camber, toe, caster, kingpin (deg), track_change, wheelbase_change,
        scrub_radius, caster_trail (m)), "roll_centre" (y, z of an axle), "notes", "written" and
        "text" (the command's report).
        """
        return _codyna._kc(self._study, _given(options))

    def simulate(
        self,
        *,
        t_end=None,
        integrator=None,
        rtol=None,
        atol=None,
        max_step=None,
        output_step=None,
        alf_penalty=None,
        alf_iterations=None,
        alf_fixed_step=None,
        alf_extrapolate=None,
        controller=None,
        open_loop=None,
        lqr=None,
        lqr_controllable_part=None,
        q_weights=None,
        r_weights=None,
        operating_point=None,
        compare_linear=None,
        linear_region=None,
        independent=None,
        hold=None,
        initial=None,
        trim_free=None,
        free_input=None,
        free_inputs=None,
        target=None,
        targets=None,
        steady_body=None,
        speed=None,
        yaw_rate=None,
        radius=None,
        lateral_acceleration=None,
        inputs=None,
        outputs=None,
        disable_effect=None,
        reference=None,
        disturbance=None,
        max_samples=None,
        divergence_bound=None,
    ):
        """Simulates the nonlinear model with its controller in the loop, as `codyna simulate`.

        Returns a Simulation: t, q, v, x (= [q v]), u, y (numpy, one row per sample) with their
        names, y_linear (compare_linear=True, else None), completed, failure, controller,
        lqr_gain, operating_point, linear_region, notes, warnings, and save(path, csv=None),
        which writes the command line's HDF5 (and CSV). A run whose integrator fails is
        returned with completed=False and the reason in failure (its samples up to then kept;
        a RuntimeWarning says so). Ctrl+C stops the run and raises KeyboardInterrupt.

        Every keyword is a flag of `codyna simulate` (dashes become underscores); one left out
        (or None) keeps the model file's choice (its "solver" and "analysis" sections):

        t_end             end time, s
        integrator        one of codyna.integrators: @INTEGRATORS@
        rtol, atol        tolerances
        max_step          largest step, s (rk4, and alf with alf_fixed_step: its fixed step)
        output_step       output interval, s
        alf_penalty, alf_iterations   alf: the constraints' penalty (> 0, default 1e11) and the
                          most Newton iterations a step (>= 1, default 100)
        alf_fixed_step    True: alf steps max_step (default 1 ms) with no error control
        alf_extrapolate   True: alf combines each step from finer trapezoidal steps (Richardson's
                          extrapolation: fourth order; at fixed steps the step and two halves, with
                          error control two halves and four quarters)
        controller        a controller .mat: K (state feedback), Kp/Ki/Kd (PID) or Ac, Bc, Cc, Dc
                          [, Ts] (LTI); default the model file's controller
        open_loop         True: ignore the model's controller (actuators at their nominal values)
        lqr               True: design an LQR on the linearized plant and use it
        lqr_controllable_part  with lqr on a plant that is not stabilizable: the controllable part
        q_weights, r_weights   LQR weights (diagonals of Q and R)
        operating_point   where the controller's plant is linearized: "initial", "equilibrium",
                          "trim" or "time=T"
        compare_linear    True: also run the linear closed loop from the same start (y_linear)
        linear_region     R (rad or m): report when the run goes farther than R from the
                          operating point (linear_region)
        independent       closed loops: the independent coordinates of the linearization
        hold              {name: value}: coordinates held in the operating-point search (they
                          also move the run's start unless initial says otherwise)
        initial           {name: value}: the run's initial state (coordinates or rates)
        trim_free, free_input (free_inputs), target (targets)   the steady-state search
        inputs, outputs, disable_effect, reference, disturbance   as in linearize()
        max_samples       refuse a run that would record more output samples
        divergence_bound  end the run when a state entry grows past this

        Raises ModelError, ValueError, ConvergenceError, TypeError as linearize() does.
        """
        run = _codyna._simulate(self._study, _given(locals()))
        if not run.completed:
            import warnings

            warnings.warn("codyna: the run failed: %s (the samples up to it are kept)" % run.failure,
                          RuntimeWarning, stacklevel=2)
        return run

    def sweep(
        self,
        vary=None,
        *,
        samples=None,
        seed=None,
        threads=None,
        redesign=None,
        simulate=None,
        out=None,
        csv=None,
        mat=None,
        restart=None,
        resume=None,
        shard=None,
        progress=None,
    ):
        """A parameter study, as `codyna sweep` runs it (docs/parameter-studies.md).

        Every variant is the model file with some numbers replaced, linearized (and its loop
        closed) by the file's "analysis" choices. The variants are edits of the file's text (of
        the JSON text for a Study.from_json), read again by the core as the command reads it.
        Returns a Sweep: fields, values (n x k), status, status_text, reasons, A, B, C, D (n x
        nx x nx ...; NaN for a failed variant, as the HDF5 file), open_poles, open_max_real,
        closed_poles, closed_max_real (complex / float, None without a closed loop), stable,
        uncontrollable, K (nu x nx fixed, n x nu x nx redesigned), with simulate=True the
        figures of merit (sim_status, t_reached, peak_input, final_error, overshoot,
        settling_time, saturation_time), the names, summary (the printed summary), worst, and
        written (the files written).

        The keywords are the flags of `codyna sweep` (dashes become underscores):

        vary        FIELD=SPEC: "FIELD=SPEC" strings (one, or a list), or a dict {field: spec}
                    whose spec is a SPEC str ("5:15:11", "[1,2]", "normal(10,3)",
                    "uniform(a,b)"), a sequence of numbers (the values listed) or a number.
                    FIELD is a JSON pointer into the model file (/bodies/1/mass)
        samples     random studies: the number of variants
        seed        random studies: the seed (variant i depends only on the specs, the seed, i)
        threads     worker threads (default: every core)
        redesign    "lqr": design the study's LQR again for every variant (default: the
                    nominal model's K, fixed)
        simulate    True: also run every variant's nonlinear closed loop
        out, csv    HDF5 results and the per-variant CSV (str or os.PathLike), written by
                    the core as the command writes them; with out, an interrupted study
                    started again resumes from its journal OUT.partial
        mat         DIR/NAME.mat (+ NAME.m) for MATLAB/Octave
        restart     True: ignore the journal of an interrupted run (resume=False says the same)
        shard       (K, N) or "K/N" (as --shard K/N): run only the variants i with i % N == K
                    (0 <= K < N, K counting from 0) and write them to out as a shard file (no
                    csv or mat; resumed as a journal is); sweep_merge joins the shards.
                    "slurm" (as --shard slurm): a Slurm job array task's, K = SLURM_ARRAY_TASK_ID
                    - SLURM_ARRAY_TASK_MIN, N = SLURM_ARRAY_TASK_COUNT (a ValueError outside an
                    array or for values that are not such a shard). The
                    Sweep returned holds the shard's variants only (indices: their numbers in
                    the study; summary: the command's one line; progress counts the
                    shard's variants). Not for a Study.from_json
                    (the merge reads the model file again)
        progress    a callable progress(done, total), called on this thread (at most every
                    50 ms, and once at the end) as variants finish; an exception it raises
                    stops the study and is raised

        A variant that fails is recorded (status, reasons) and never stops the study. The
        sweep releases the GIL; Ctrl+C stops it (no new variant is started; with out, the
        journal keeps those done) and raises KeyboardInterrupt.

        Raises ModelError (a bad nominal model), ValueError (a bad keyword value, naming the
        keyword: vary and the field, samples, seed ...), ConvergenceError (the nominal
        operating point does not converge), TypeError (an unknown keyword or a wrong type).
        """
        options = _given(locals())
        return _codyna._sweep(self._study, options)


def sweep_merge(shards, *, out, csv=None, mat=None):
    """Joins the shards of Study.sweep(shard=(K, N)) (or of `codyna sweep --shard K/N`) into the
    files the whole study run at once writes, byte for byte, as `codyna sweep-merge SHARD... --out
    OUT [--csv CSV] [--mat DIR/NAME.mat]` does (the same core call).

    shards      the shards' files: a list of str or os.PathLike (or one path)
    out         the merged HDF5 results (required)
    csv, mat    as in Study.sweep

    The shards must be of one study (the same model file bytes and options) and hold every
    variant between them; the model file is read again from the path the shards name (relative
    paths from the current folder). Returns the whole study's Sweep (no variant is run again).
    Raises ValueError with the command's message: a shard missing ("variants ... are in none of
    the shards given"), a shard of another study, a file that is not a shard, an output that
    would replace an input; TypeError for a wrong type.
    """
    return _codyna._sweep_merge(shards, _given(dict(out=out, csv=csv, mat=mat)))


# the integrators' names in simulate()'s docstring, from the core's one list
Study.simulate.__doc__ = Study.simulate.__doc__.replace("@INTEGRATORS@", ", ".join(f'"{n}"' for n in integrators))
