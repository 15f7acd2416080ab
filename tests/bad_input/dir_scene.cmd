render adir.exr
