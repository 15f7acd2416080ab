compare ref_fov.exr ref_ok.exr --strict
