"""Quick start (c): a third-party bogie at the axle boxes, from the shipped SSP, in two
co-simulation masters, OSP libcosim (libcosimpy) and ecos (ecospy).

    .venv/bin/python python/quickstart/bogie_in_masters.py

RollPlaneVehicle stands in for the bogie: TrackContact carries the wheelsets on their
primary suspensions, the bogie gets the primary forces and returns its side frames'
motion, at the SSP's 1 ms step. Prints each master's peak contact forces and their
difference from CoupledSystem's (the whole model in one FMU, on the SSP's parameters).
"""
import os, re, shutil, sys, tempfile, time, zipfile
import xml.etree.ElementTree as ET
from ecospy import EcosLib, EcosSimulation
from fmpy import read_model_description, simulate_fmu
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver

# The repository's paths (fmu/ as python3 python/couple.py builds it), from wherever it runs.
os.chdir(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
if not os.path.exists("fmu/CoupledSystem.fmu"):
    sys.exit("no fmu/CoupledSystem.fmu: build the FMUs first (python3 python/couple.py)")
SSP = "fmu/systems/TrackContact_RollPlaneVehicle_axle_box.ssp"
MAX = ["contact.left.max_force", "contact.right.max_force"]  # TrackContact's running maxima
OUT = MAX + ["position"]  # and where the track is at the end
t0 = time.perf_counter()

# The SSP's own settings: its step (the OSP annotation), stop time and parameters.
ssd = zipfile.ZipFile(SSP).read("SystemStructure.ssd").decode()
step = float(re.search(r'baseStepSize="([^"]+)"', ssd).group(1))
stop = float(re.search(r'<ssd:DefaultExperiment [^>]*stopTime="([^"]+)"', ssd).group(1))
ns = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
      "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues"}
params = {c.get("name"): {p.get("name"): float(p[0].get("value")) for p in c.iter(f"{{{ns['ssv']}}}Parameter")}
          for c in ET.fromstring(ssd).iter(f"{{{ns['ssd']}}}Component")}
print(f"{SSP}: step {step * 1e3:g} ms to {stop} s; TrackContact's parameters:")
print("  " + ", ".join(f"{k} = {v:.10g}" for k, v in params["TrackContact"].items()))

# CoupledSystem with TrackContact's parameters that it has (not `interface`).
md = read_model_description("fmu/CoupledSystem.fmu")
own = {v.name for v in md.modelVariables if v.causality in ("parameter", "input")}
r = simulate_fmu("fmu/CoupledSystem.fmu", stop_time=stop, output_interval=step, output=MAX,
                 start_values={k: v for k, v in params["TrackContact"].items() if k in own})
results = {"CoupledSystem": [float(r[x][-1]) for x in MAX]}

# libcosim: the SSP as it is (its step, its parameter set); components named after their FMUs.
log_output_level(CosimLogLevel.WARNING)
ex = CosimExecution.from_ssp_file(SSP)
last = CosimObserver.create_last_value()
ex.add_observer(last)
track = ex.slave_index_from_instance_name("TrackContact")
vr = {v.name.decode(): v.reference for v in ex.slave_variables(track)}
assert ex.simulate_until(round(stop * 1e9)), "libcosim stopped: an FMU refused a step"
results["libcosim"] = last.last_real_values(track, [vr[x] for x in OUT])

# ecos: the step from Python, the parameter set by name; it unpacks the SSP under $TMPDIR.
os.environ["TMPDIR"] = tmp = tempfile.mkdtemp()
EcosLib.set_log_level("warn")
try:
    sim = EcosSimulation(ssp_path=SSP, step_size=step)
    sim.init(parameter_set="wheelflat")  # without the name no SSP parameter is applied
    sim.step(round(stop / step))
    results["ecos"] = [sim.get_real("TrackContact::" + x) for x in OUT]
    sim.terminate()
    sim.free()
finally:
    shutil.rmtree(tmp, ignore_errors=True)
# ecos ignores every status: check that its track went as far as libcosim's.
assert abs(results["ecos"].pop() - results["libcosim"].pop()) < 1e-9, "ecos: the track stopped"

print("peak contact force (kN), leading wheelset, and the difference from CoupledSystem's:")
for master, peaks in results.items():
    line = f"  {master:14} left {peaks[0] / 1e3:6.1f}, right {peaks[1] / 1e3:6.1f}"
    if master != "CoupledSystem":
        d = [p - q for p, q in zip(peaks, results["CoupledSystem"])]
        line += "   " + ", ".join(f"{s} {x / 1e3:+.1f} kN ({100 * x / q:+.2f} %)" for s, x, q in
                                  zip(("left", "right"), d, results["CoupledSystem"]))
    print(line)
print(f"wall time: {time.perf_counter() - t0:.1f} s")
