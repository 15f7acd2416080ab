batch adir.exr
