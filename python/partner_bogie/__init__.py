"""Issue 41: a stand-in for a third party's half-car bogie, exported with pythonfmu
(standin_half_car.py, built by build.py), and the coupling matrix that runs it with
TrackContact at the axle boxes in four masters (matrix.py)."""
