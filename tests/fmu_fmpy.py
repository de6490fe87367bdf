"""Checks of bondmech's FMUs with FMPy, an independent importer (run by tests/fmu.rs).

    python3 tests/fmu_fmpy.py CHECK BONDMECH_EXE

Each check exports FMUs with `bondmech fmu`, simulates them with FMPy and compares the
results with `bondmech run` of the same scene (the CLI is the reference: the FMU must be the
same solver underneath). A failed check raises (non-zero exit) with what differed.
"""

import atexit
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile

import numpy as np
import fmpy
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

try:
    from fmpy.validation import validate_fmu
except ImportError:  # older FMPy
    from fmpy import validate_fmu

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(ROOT, "scenes")
BONDMECH = sys.argv[2]
TMP = tempfile.mkdtemp(prefix="bondmech-fmu-")
CLEANUP = [TMP]
atexit.register(lambda: [shutil.rmtree(d, ignore_errors=True) for d in CLEANUP])


def scene(name):
    return os.path.join(SCENES, name + ".json")


def sh(*args):
    r = subprocess.run([BONDMECH, *args], capture_output=True, text=True)
    assert r.returncode == 0, f"bondmech {' '.join(args)} failed: {r.stderr}"
    return r.stdout


def export(path, out, fmi="3", *flags):
    out = os.path.join(TMP, out)
    sh("fmu", path, "--out", out, "--fmi", fmi, *flags)
    return out


def run_csv(path, *flags):
    out = os.path.join(TMP, "run.csv")
    sh("run", path, "--out", out, *flags)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def compare(result, reference, rel, what):
    """Largest difference of every output column relative to the column's size (columns that
    stay at rounding-error size, like a slider's off-axis coordinate, count against 1e-6 of the
    largest column), asserted below `rel`."""
    t = reference["t"]
    assert len(result) == len(t), f"{what}: {len(result)} rows, the CLI wrote {len(t)}"
    assert np.allclose(result["time"], t, rtol=0, atol=1e-12), f"{what}: other output times"
    names = result.dtype.names[1:]
    floor = 1e-6 * max(np.max(np.abs(reference[n])) for n in names)
    worst = (0.0, None)
    for n in names:
        a, b = reference[n], result[n]
        scale = max(np.max(np.abs(a)), floor)
        e = np.max(np.abs(a - b)) / scale
        if e > worst[0]:
            worst = (e, n)
    assert worst[0] <= rel, f"{what}: column {worst[1]} differs by {worst[0]:.3e} relative (> {rel:g})"
    print(f"{what}: {len(t)} rows, {len(names)} columns, largest relative difference {worst[0]:.3e}")
    return worst[0]


def check_validate():
    """Every bundled scene exports as a valid FMI 2.0 and FMI 3.0 FMU, laid out as the
    standard says."""
    names = sorted(f[:-5] for f in os.listdir(SCENES) if f.endswith(".json"))
    assert len(names) >= 15, names
    for name in names:
        for fmi, platform in (("2", "linux64"), ("3", "x86_64-linux")):
            fmu = export(scene(name), f"{name}-{fmi}.fmu", fmi)
            problems = validate_fmu(fmu)
            assert problems == [], f"{name} FMI {fmi}: {problems}"
            with zipfile.ZipFile(fmu) as z:
                files = set(z.namelist())
                md = z.read("modelDescription.xml").decode()
            for f in ("modelDescription.xml", f"binaries/{platform}/bondmech_fmu.so",
                      "resources/scene.json", "resources/bondmech-fmu.json",
                      "documentation/index.html"):
                assert f in files, f"{name} FMI {fmi}: {f} missing from {sorted(files)}"
            assert f'fmiVersion="{fmi}.0"' in md
            d = read_model_description(fmu)
            outputs = [v for v in d.modelVariables if v.causality == "output"]
            assert outputs, f"{name}: no outputs"
            if fmi == "3":
                # and it runs: two communication steps, the rows of `bondmech run`
                h = float(d.defaultExperiment.stepSize)
                r = fmpy.simulate_fmu(fmu, stop_time=2 * h, output_interval=h)
                ref = run_csv(scene(name), "--set", f"solve.output_step={h!r}",
                              "--t-end", repr(2 * h))
                compare(r, ref, 1e-9, f"{name}, two steps")
            os.remove(fmu)
        print(f"{name}: FMI 2.0 and 3.0 valid")


def check_run():
    """FMPy's simulation of the double pendulum and the slider-crank (communication step
    1e-2 s) equals `bondmech run` at the same output times."""
    for name in ("double_pendulum", "slider_crank"):
        reference = run_csv(scene(name), "--set", "solve.output_step=0.01")
        for fmi in ("3", "2"):
            fmu = export(scene(name), f"{name}-{fmi}.fmu", fmi)
            t_end = read_model_description(fmu).defaultExperiment.stopTime
            r = fmpy.simulate_fmu(fmu, stop_time=float(t_end), output_interval=0.01)
            compare(r, reference, 1e-9, f"{name} FMI {fmi}")


def tight_input_scenes():
    """The input-driven slider-crank at tight tolerances, and its twin with the torque as a
    step expression of t (0 N m, then -0.5 N m from t = 0.5 s)."""
    s = json.load(open(scene("slider_crank_input")))
    s["solve"].update(rtol=1e-11, atol=1e-13, output_step=0.01)
    with_input = os.path.join(TMP, "sc_input.json")
    json.dump(s, open(with_input, "w"))
    del s["inputs"]
    for load in s["loads"]:
        if load["name"] == "drive":
            load["value"] = "0 - 0.5*min(1, max(0, (t - 0.5)*1e12))"
    with_step = os.path.join(TMP, "sc_step.json")
    json.dump(s, open(with_step, "w"))
    return with_input, with_step


def check_input():
    """A torque input stepped by FMPy equals the CLI run of the scene with the torque written
    as a step expression of t; held at its start value it equals the plain run.

    The FMU replays the solve with the input's history as a step function of t (its first
    input changes do, docs/fmu.md); the step's ramp and the output times differ from the CLI's
    by a hair, so the two integrations agree to the solver's accuracy: at rtol 1e-11 (the
    tolerances of the test) 3.2e-11, at the scene's rtol 1e-8 1.5e-9."""
    with_input, with_step = tight_input_scenes()
    reference = run_csv(with_step)
    constant = run_csv(with_input)
    step = np.array([(0.0, 0.0), (0.5, 0.0), (0.5, -0.5), (1.0, -0.5)],
                    dtype=[("time", np.float64), ("torque", np.float64)])
    for fmi in ("3", "2"):
        fmu = export(with_input, f"sc-input-{fmi}.fmu", fmi)
        r = fmpy.simulate_fmu(fmu, stop_time=1.0, output_interval=0.01, input=step)
        compare(r, reference, 1e-8, f"stepped torque input, FMI {fmi}")
        # the step matters: the run at the start value is far from it
        late = reference["crank.angle"][-1] - constant["crank.angle"][-1]
        assert abs(late) > 0.1, late
        r = fmpy.simulate_fmu(fmu, stop_time=1.0, output_interval=0.01)
        compare(r, constant, 1e-9, f"torque input at its start value, FMI {fmi}")


def check_parameter():
    """`bodies[bar2].mass` set through the FMU equals `run --set` with the same value."""
    path = scene("double_pendulum")
    for fmi in ("3", "2"):
        fmu = export(path, f"dp-mass-{fmi}.fmu", fmi, "--parameter", "bodies[bar2].mass")
        r = fmpy.simulate_fmu(fmu, stop_time=1.0, output_interval=0.01,
                              start_values={"bodies[bar2].mass": 2.5})
        reference = run_csv(path, "--set", "bodies[bar2].mass=2.5", "--t-end", "1")
        compare(r, reference, 1e-9, f"bodies[bar2].mass = 2.5, FMI {fmi}")
        unchanged = run_csv(path, "--t-end", "1")
        moved = np.max(np.abs(unchanged["bar2.angle"] - r["bar2.angle"]))
        assert moved > 1e-2, f"the mass made no difference ({moved})"


def slave(version, fmu, name):
    md = read_model_description(fmu)
    unzipped = extract(fmu)
    CLEANUP.append(unzipped)
    cls = FMU3Slave if version == "3" else FMU2Slave
    s = cls(guid=md.guid, unzipDirectory=unzipped,
            modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    outputs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
    return s, vrs, outputs


def start(version, s, vrs, params, instantiate=True):
    if instantiate:
        s.instantiate()
    if version == "3":
        s.enterInitializationMode(startTime=0.0, stopTime=1.0)
        for k, v in params.items():
            s.setFloat64([vrs[k]], [v])
    else:
        s.setupExperiment(startTime=0.0, stopTime=1.0)
        for k, v in params.items():
            s.setReal([vrs[k]], [v])
        s.enterInitializationMode()
    s.exitInitializationMode()


def get(version, s, outputs):
    return np.array(s.getFloat64(outputs) if version == "3" else s.getReal(outputs))


def check_instances():
    """Two instances in one process, stepped in turn with different parameters, give the
    results of each alone."""
    path = scene("double_pendulum")
    for version in ("3", "2"):
        fmu = export(path, f"dp-two-{version}.fmu", version, "--parameter", "bodies[bar2].mass")
        alone = {}
        for mass in (1.0, 2.5):
            r = fmpy.simulate_fmu(fmu, stop_time=1.0, output_interval=0.01,
                                  start_values={"bodies[bar2].mass": mass})
            alone[mass] = np.array([list(row)[1:] for row in r])
        a, vrs, outputs = slave(version, fmu, "a")
        b, _, _ = slave(version, fmu, "b")
        start(version, a, vrs, {"bodies[bar2].mass": 1.0})
        start(version, b, vrs, {"bodies[bar2].mass": 2.5})
        rows = {1.0: [get(version, a, outputs)], 2.5: [get(version, b, outputs)]}
        for k in range(100):
            t = k * 0.01
            for s, mass in ((a, 1.0), (b, 2.5)):
                s.doStep(currentCommunicationPoint=t, communicationStepSize=0.01)
                rows[mass].append(get(version, s, outputs))
        for s in (a, b):
            s.terminate()
            s.freeInstance()
        for mass in (1.0, 2.5):
            together = np.array(rows[mass])
            d = np.max(np.abs(together - alone[mass]))
            assert d == 0.0, f"FMI {version}, mass {mass}: two at once differ from alone by {d}"
        assert np.max(np.abs(alone[1.0] - alone[2.5])) > 1e-2
        print(f"FMI {version}: two instances at once equal each alone (101 rows each)")


KEEP = []  # ctypes callbacks that must outlive the instances using them


def check_failure():
    """A solve that fails inside a step returns an error status with a message naming the
    element and the time; the importer goes on (the failed instance answers its getters,
    another FMU simulates)."""
    s = json.load(open(scene("slider_crank")))
    for load in s["loads"]:
        if load["name"] == "gas":
            load["value"] = ["0", "-10*sqrt(0.3 - t)"]
    failing = os.path.join(TMP, "sc_fails.json")
    json.dump(s, open(failing, "w"))
    good = export(scene("double_pendulum"), "dp-good.fmu", "3")
    for version in ("3", "2"):
        fmu = export(failing, f"sc-fails-{version}.fmu", version)
        # through FMPy's simulate_fmu: an exception naming the failed call
        try:
            fmpy.simulate_fmu(fmu, stop_time=1.0, output_interval=0.01)
            raise AssertionError("the failing solve did not fail")
        except FMICallException as e:
            assert "DoStep" in str(e) and "status 3" in str(e), str(e)
        # step by step, with a logger that keeps the messages
        messages = []
        s, vrs, outputs = slave(version, fmu, "failing")
        if version == "3":
            s.instantiate(logMessage=lambda env, status, cat, msg: messages.append((status, msg.decode())))
        else:
            # FMPy formats FMI 2.0's variadic messages through a native proxy that holds the
            # last logger registered: this one is kept alive for the rest of the process
            from fmpy.fmi2 import (fmi2CallbackFunctions, fmi2CallbackLoggerTYPE,
                                   fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE)
            from fmpy.fmi1 import calloc, free
            from fmpy.logging import addLoggerProxy
            from ctypes import byref
            callbacks = fmi2CallbackFunctions()
            callbacks.logger = fmi2CallbackLoggerTYPE(
                lambda env, name, status, cat, msg: messages.append((status, msg.decode())))
            callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
            callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
            addLoggerProxy(byref(callbacks))
            KEEP.append(callbacks)
            s.instantiate(callbacks=callbacks)
        start(version, s, vrs, {}, instantiate=False)
        failed_at = None
        for k in range(40):
            try:
                s.doStep(currentCommunicationPoint=k * 0.01, communicationStepSize=0.01)
            except FMICallException as e:
                assert "status 3" in str(e), str(e)
                failed_at = k * 0.01
                break
        assert failed_at is not None, "no step failed"
        assert 0.29 <= failed_at <= 0.3, failed_at
        errors = [m for status, m in messages if status == 3]
        assert errors, f"no error logged: {messages}"
        assert "gas" in errors[-1] and "t = 0.3" in errors[-1], errors[-1]
        print(f"FMI {version}: error status, logged: {errors[-1]}")
        # the failed instance still answers (the state before the failed step), and refuses
        # to step on
        values = get(version, s, outputs)
        assert np.all(np.isfinite(values)), values
        try:
            s.doStep(currentCommunicationPoint=failed_at, communicationStepSize=0.01)
            raise AssertionError("a failed instance stepped on")
        except FMICallException:
            pass
        s.freeInstance()
    r = fmpy.simulate_fmu(good, stop_time=0.1, output_interval=0.01)
    compare(r, run_csv(scene("double_pendulum"), "--t-end", "0.1"), 1e-9,
            "after the failures, another FMU")


def check_state():
    """An FMU state taken at t = 0.5 (kept, or serialised and read back) and restored continues
    exactly as the instance did."""
    path = scene("slider_crank_input")
    for version in ("3", "2"):
        fmu = export(path, f"sc-state-{version}.fmu", version)
        s, vrs, outputs = slave(version, fmu, "state")
        start(version, s, vrs, {})
        set_input = (lambda x: s.setFloat64([vrs["torque"]], [x])) if version == "3" else \
            (lambda x: s.setReal([vrs["torque"]], [x]))
        h = 0.01
        for k in range(50):
            set_input(1.5 + 0.02 * k)
            s.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
        if version == "3":
            state = s.getFMUState()
            blob = s.serializeFMUState(state)
        else:
            state = s.getFMUstate()
            blob = s.serializeFMUstate(state)

        def rest():
            out = []
            for k in range(50, 100):
                set_input(1.5 - 0.01 * k)
                s.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
                out.append(get(version, s, outputs))
            return np.array(out)

        first = rest()
        if version == "3":
            s.setFMUState(state)
            again = rest()
            s.setFMUState(s.deserializeFMUState(blob))
            third = rest()
            s.freeFMUState(state)
        else:
            s.setFMUstate(state)
            again = rest()
            s.setFMUstate(s.deSerializeFMUstate(blob))
            third = rest()
            s.freeFMUstate(state)
        s.terminate()
        s.freeInstance()
        for other, how in ((again, "restored"), (third, "deserialised")):
            d = np.max(np.abs(other - first))
            assert d == 0.0, f"FMI {version}: the {how} state continues {d} away"
        print(f"FMI {version}: the restored and the deserialised state continue exactly "
              f"({len(blob)} bytes serialised)")


def check_driver_input():
    """A rate driver whose speed is an input: the crank of the driven slider-crank turns at the
    speed FMPy sets, 10 rad/s until 0.25 s and 6 rad/s after. The crank angle is then the
    integral of the steps, θ0 + 10 t before and θ0 + 2.5 + 6 (t − 0.25) after (exact, not a
    bondmech run)."""
    s = json.load(open(scene("slider_crank_driven")))
    th0 = s["bodies"][0]["angle"]
    s["inputs"] = [{"name": "speed", "start": 10.0, "unit": "rad/s"}]
    s["drivers"] = [{"name": "motor", "joint": "main_bearing", "angular_velocity": "speed"}]
    s["solve"].update({"t_end": 0.5, "output_step": 0.01, "rtol": 1e-10, "atol": 1e-12})
    path = os.path.join(TMP, "sc_driver_input.json")
    json.dump(s, open(path, "w"))
    speed = np.array([(0.0, 10.0), (0.25, 10.0), (0.25, 6.0), (0.5, 6.0)],
                     dtype=[("time", np.float64), ("speed", np.float64)])
    for fmi in ("3", "2"):
        fmu = export(path, f"sc-driver-input-{fmi}.fmu", fmi)
        r = fmpy.simulate_fmu(fmu, stop_time=0.5, output_interval=0.01, input=speed)
        t = r["time"]
        exact = np.where(t <= 0.25, th0 + 10.0 * t, th0 + 2.5 + 6.0 * (t - 0.25))
        err = np.max(np.abs(r["crank.angle"] - exact))
        assert err < 1e-8, f"FMI {fmi}: crank angle {err:.3e} rad from the integrated steps"
        # the torque is finite everywhere (a kinematic analysis between the steps)
        assert np.all(np.isfinite(r["motor.torque"])), "non-finite motor torque"
        print(f"FMI {fmi}: a stepped driver speed, crank angle within {err:.2e} rad of the "
              f"integrated steps over {len(t)} rows")


if __name__ == "__main__":
    globals()["check_" + sys.argv[1]]()
