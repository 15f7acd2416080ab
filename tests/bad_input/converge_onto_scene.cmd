converge conv.json --reference half.exr -o conv --estimators power
