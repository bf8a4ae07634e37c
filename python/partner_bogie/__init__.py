"""Issue 41: a stand-in for a third party's half-car bogie, exported with pythonfmu
(standin_half_car.py, built by build.py), and the coupling matrix that runs it with
TrackContact at the axle boxes in four masters (matrix.py). Issue 43: the same bogie
exported with pythonfmu3 as an FMI 3.0 FMU with arrays of its own (standin_half_car3.py,
build.py --fmi 3), coupled with the FMI 3.0 TrackContact (couple3.py); both exports step
the one model of standin_bogie.py."""
