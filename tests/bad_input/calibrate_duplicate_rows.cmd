calibrate counters_min.csv counters_copy.csv timings_min.csv -o calib_out/c.json
