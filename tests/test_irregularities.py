"""Measured irregularities through the FMUs: rail profiles and wheel out-of-roundness
named by String parameters (the table itself, or its file), set by fmpy, OSP libcosim
and ecos from an SSP parameter set; the dipped weld; refusals by name; FMU states that
carry the tables (docs/MODEL.md, "Measured irregularities")."""

import math
import os
import sys
import zipfile

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import wheelflat_fmus as wf  # noqa: E402

from fmpy import simulate_fmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402

# A perfect wheel at CoupledSystem's 70 km/h from 1.37 m: 0.5 s takes it to 11.1 m.
PERFECT = {"flat.left[1].depth": 0.0, "flat.left[1].length": 0.0}
# A 2 mm dip between 8 and 9 m, as a table.
DIP = "0 0; 8 0; 8.5 -2e-3; 9 0; 30 0"


@pytest.fixture(scope="module")
def coupled():
    path = os.path.join(wf.FMU_DIR, "CoupledSystem.fmu")
    return path if os.path.exists(path) else wf.build_fmus()["CoupledSystem"]


def force(path, **start):
    r = simulate_fmu(path, stop_time=0.5, output_interval=1e-3, start_values={**PERFECT, **start},
                     output=["contact.left.force", "contact.left.max_force", "position", "wheel.rotation"])
    return r


def test_a_rail_profile_given_inline_or_as_a_file_gives_the_same_forces(coupled, tmp_path):
    plain = force(coupled)
    inline = force(coupled, **{"rail.left.profile": DIP})
    table = tmp_path / "dip.txt"
    table.write_text("# position (m)  height (m)\n" + DIP.replace("; ", "\n") + "\n")
    filed = force(coupled, **{"rail.left.profile": str(table)})
    assert np.array_equal(inline["contact.left.force"], filed["contact.left.force"])
    # The dip is felt: the wheel drops into it and is thrown back (13 kN above the
    # plain run's largest force).
    assert inline["contact.left.max_force"][-1] > plain["contact.left.max_force"][-1] + 10e3


def test_a_wheel_deviation_and_the_rail_profile_of_the_same_geometry_agree(coupled):
    # Hertz contact. A 2 mm, 1 m long dip on the left wheel's running surface (wheel
    # angles 1.39 to 3.50 rad), and on the left rail the same dip wherever x = x_0 +
    # R beta puts that part of the wheel on it, once a turn (x_0 = 1.37 m, R = 0.475
    # m: from 2.03, 5.02, 8.00 and 10.98 m): the contact sees the same geometry, and
    # the forces over the run's 3.3 turns agree to 1e-6 of the static load (the
    # issue asks 1 %).
    x0, r = 1.37, 0.475
    b0, b1 = ((8.0 - x0) / r) % (2 * math.pi), ((9.0 - x0) / r) % (2 * math.pi)
    bm = 0.5 * (b0 + b1)
    wheel = f"0 0; {b0!r} 0; {bm!r} -2e-3; {b1!r} 0; 6.28 0"
    rail = ["0 0"]
    for k in range(4):
        rail += [f"{x0 + r * (b + 2 * math.pi * k)!r} {h!r}" for b, h in ((b0, 0.0), (bm, -2e-3), (b1, 0.0))]
    rail.append("30 0")
    a = force(coupled, **{"contact.model": 2, "rail.left.profile": "; ".join(rail)})
    b = force(coupled, **{"contact.model": 2, "wheel.left.out_of_roundness": wheel})
    load = a["contact.left.force"][0]
    assert np.abs(a["contact.left.force"] - b["contact.left.force"]).max() < 1e-6 * load
    assert a["contact.left.max_force"][-1] > 1.1 * load, "the dips are felt"


def test_the_dipped_weld_is_the_same_dip_as_a_table(coupled):
    weld = force(coupled, **{"rail.defect.position": 8.5, "rail.defect.length": 1.0,
                             "rail.defect.left.depth": 1e-3})
    x = np.linspace(8.0, 9.0, 501)
    h = -0.5e-3 * (1 + np.cos(2 * np.pi * (x - 8.5)))
    table = "0 0; " + "; ".join(f"{a:.17g} {b:.17g}" for a, b in zip(x, h)) + "; 30 0"
    same = force(coupled, **{"rail.left.profile": table})
    load = weld["contact.left.force"][0]
    assert np.abs(weld["contact.left.force"] - same["contact.left.force"]).max() < 1e-3 * load


@pytest.mark.parametrize("name, value, message", [
    ("rail.left.profile", "0 0; 8 x", "rail.left.profile: line 1, its point 2 after a `;`: 2 fields that are not both numbers"),
    ("rail.left.profile", "0,0;8,0;8.5,-2e-3#dip;9,0;30,0", "a `#` in a table on one line"),
    ("rail.left.profile", "/no/such/table.txt", 'rail.left.profile = "/no/such/table.txt": cannot read'),
    ("rail.right.profile", "0 0; 1 0.02", "rail.right.profile (height)"),
    ("rail.left.profile", "0 0; 0 1e-4", "point 2"),
    ("wheel.left.out_of_roundness", "0 0; 7 1e-4", "wheel.left.out_of_roundness (wheel angle)"),
    ("wheel.right.out_of_roundness", "0 0; 1 0.01", "wheel.right.out_of_roundness (radius deviation)"),
    ("rail.left.profile", "/tmp", 'rail.left.profile = "/tmp": not a regular file'),
])
def test_a_bad_table_is_refused_when_it_is_set_with_its_name(coupled, capfd, name, value, message):
    with pytest.raises(FMICallException):
        simulate_fmu(coupled, stop_time=0.01, start_values={name: value})
    out = capfd.readouterr().out
    assert "fmi2SetString" in out and message in out, out


def test_a_pipe_is_refused_without_waiting_for_it(coupled, capfd, tmp_path):
    # A named pipe (or a device such as /dev/zero) would block or never end.
    fifo = tmp_path / "table.fifo"
    os.mkfifo(fifo)
    with pytest.raises(FMICallException):
        simulate_fmu(coupled, stop_time=0.01, start_values={"rail.left.profile": str(fifo)})
    assert "not a regular file" in capfd.readouterr().out
    with pytest.raises(FMICallException):
        simulate_fmu(coupled, stop_time=0.01, start_values={"rail.left.profile": "/dev/zero"})
    assert "not a regular file" in capfd.readouterr().out


def test_a_dipped_weld_shorter_than_the_patch_allows_is_refused(coupled, capfd):
    with pytest.raises(FMICallException):
        simulate_fmu(coupled, stop_time=0.01, start_values={"rail.defect.length": 0.05})
    assert "`rail.defect.length` = 0.05 m is out of range" in capfd.readouterr().out


def test_an_fmu_state_carries_the_tables_into_a_fresh_instance(coupled):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(coupled)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    d = extract(coupled)

    def instance():
        f = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="tables")
        f.instantiate()
        return f

    a = instance()
    a.setupExperiment(startTime=0.0)
    a.setString([vr["rail.left.profile"]], [DIP])
    a.setReal([vr["flat.left[1].depth"], vr["flat.left[1].length"]], [0.0, 0.0])
    a.enterInitializationMode()
    a.exitInitializationMode()
    assert a.getString([vr["rail.left.profile"]]) == [DIP.encode()]
    h, t = 1e-3, 0.0
    for _ in range(300):
        a.doStep(t, h)
        t += h
    blob = a.serializeFMUstate(a.getFMUstate())
    b = instance()
    b.setFMUstate(b.deSerializeFMUstate(blob))
    assert b.getString([vr["rail.left.profile"]]) == [DIP.encode()]
    out = [vr["contact.left.force"]]
    for _ in range(200):
        a.doStep(t, h)
        b.doStep(t, h)
        t += h
        assert a.getReal(out) == b.getReal(out)
    for f in (a, b):
        f.terminate()
        f.freeInstance()


def one_component_ssp(path, tmp_path, parameters):
    """An SSP of CoupledSystem alone with the parameter set `wheelflat`."""
    def value(v):
        if isinstance(v, str):
            return f'<ssv:String value="{v}"/>'
        if isinstance(v, int):
            return f'<ssv:Integer value="{v}"/>'
        return f'<ssv:Real value="{v!r}"/>'
    params = "\n".join(f'<ssv:Parameter name="{k}">{value(v)}</ssv:Parameter>' for k, v in parameters.items())
    ssd = f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" name="profile" version="1.0">
  <ssd:System name="profile">
    <ssd:Elements>
      <ssd:Component name="coupled" source="resources/CoupledSystem.fmu">
        <ssd:Connectors>
          <ssd:Connector name="contact.left.max_force" kind="output"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="wheelflat"><ssv:Parameters>
{params}
          </ssv:Parameters></ssv:ParameterSet>
        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>
      </ssd:Component>
    </ssd:Elements>
  </ssd:System>
</ssd:SystemStructureDescription>
"""
    ssp = tmp_path / "profile.ssp"
    with zipfile.ZipFile(ssp, "w") as z:
        z.writestr("SystemStructure.ssd", ssd)
        z.write(path, "resources/CoupledSystem.fmu")
    return str(ssp)


def test_libcosim_and_ecos_set_the_tables_from_an_ssp_parameter_set(coupled, tmp_path):
    # The rail's dip set as an SSP String parameter: both masters run CoupledSystem to
    # the same largest force as fmpy, at its own step.
    params = {**PERFECT, "rail.left.profile": DIP}
    expected = force(coupled, **{"rail.left.profile": DIP})["contact.left.max_force"][-1]
    ssp = one_component_ssp(coupled, tmp_path, params)
    h = 1e-3

    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.WARNING)
    ex = CosimExecution.from_ssp_file(ssp, int(h * 1e9))
    k = ex.slave_index_from_instance_name("coupled")
    refs = {v.name.decode(): v.reference for v in ex.slave_variables(k)}
    last = CosimObserver.create_last_value()
    ex.add_observer(last)
    assert ex.simulate_until(int(0.5e9))
    libcosim = last.last_real_values(k, [refs["contact.left.max_force"]])[0]

    from ecospy import EcosLib, EcosSimulation
    EcosLib.set_log_level("warn")
    sim = EcosSimulation(ssp_path=ssp, step_size=h)
    sim.init(parameter_set="wheelflat")
    sim.step(500)
    ecos = sim.get_real("coupled::contact.left.max_force")
    sim.terminate()
    sim.free()
    # Without the dip: 109.4 kN; with it 120 kN and more, in every master.
    assert libcosim == pytest.approx(expected, rel=1e-9)
    assert ecos == pytest.approx(expected, rel=1e-9)
    assert expected > 115e3
