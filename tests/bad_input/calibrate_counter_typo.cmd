calibrate counters_typo.csv timings_min.csv -o calib_out/c.json
