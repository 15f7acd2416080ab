render particles_png.toml --quiet -o clash_particles.exr
