calibrate counters_min.csv timings_semicolon.csv -o calib_out/c.json
