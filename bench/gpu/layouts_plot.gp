# The layouts table as a plot (gnuplot bench/gpu/layouts_plot.gp, from the
# repository root): left, the acceleration-structure build of a frame
# against the BLAS count it issues (clusters of 25 to all particles, one
# host thread and stream, rebuild); right, the whole restir frame at 1080p
# per layout. Reads bench/gpu/results/layouts.csv, writes layouts.png beside it.
set datafile separator ','
set terminal pngcairo size 1400,560 font ',11'
set output 'bench/gpu/results/layouts.png'
set multiplot layout 1,2 title "Seed 004's decision matrix on an H100 without RT cores (software traversal), restir at 1920x1080, frame 1 (bench/gpu/results/layouts.csv, at b34c03169a)"
set logscale xy
set grid
set key top left
set xlabel 'BLASes built per frame'
set ylabel 'build GPU ms (expand + BLAS + TLAS)'
single(p) = (strcol(5) eq '1920' && strcol(7) eq 'clusters' && strcol(8) eq 'billboard' && strcol(10) eq 'rebuild' && \
             strcol(11) eq '1' && strcol(12) eq '1' && strcol(4) eq p)
plot for [p in '10000 100000 1000000'] 'bench/gpu/results/layouts.csv' \
     using (single(p) ? column(13) : NaN):(column(20)) with linespoints pt 7 title sprintf('%s particles, triangle clusters', p), \
     '' using ((strcol(5) eq '1920' && strcol(7) eq 'instances' && strcol(10) eq 'rebuild') ? column(13) : NaN):(column(20)) \
        with points pt 5 ps 1.5 title 'one instance per particle (TLAS build)', \
     '' using ((strcol(5) eq '1920' && strcol(7) eq 'aabbs' && strcol(10) eq 'rebuild') ? column(13) : NaN):(column(20)) with points pt 9 ps 1.5 title 'procedural boxes', \
     '' using ((strcol(5) eq '1920' && strcol(8) eq 'sphere' && strcol(10) eq 'rebuild') ? column(13) : NaN):(column(20)) with points pt 11 ps 1.5 title 'built-in spheres'
unset logscale x
set logscale y
set xlabel 'particles'
set ylabel 'frame GPU ms (build + G-buffer + restir + shadow rays)'
set logscale x
set xrange [5000:2000000]
row(l, prim, k, b) = (strcol(5) eq '1920' && strcol(7) eq l && strcol(8) eq prim && strcol(9) eq k && strcol(10) eq b && \
                      strcol(11) eq '1' && strcol(12) eq '1')
plot 'bench/gpu/results/layouts.csv' using (row('clusters','billboard','100','rebuild') ? column(4) : NaN):(column(24)) w lp pt 7 title 'clusters of 100 (seed 004)', \
     '' using (row('clusters','billboard','1000','rebuild') ? column(4) : NaN):(column(24)) w lp pt 7 title 'clusters of 1000', \
     '' using (row('clusters','billboard','10000','rebuild') ? column(4) : NaN):(column(24)) w lp pt 7 title 'clusters of 10000', \
     '' using (row('clusters','billboard','all','rebuild') ? column(4) : NaN):(column(24)) w lp pt 7 title 'one triangle BLAS', \
     '' using (row('clusters','billboard','all','refit') ? column(4) : NaN):(column(24)) w lp pt 6 title 'one triangle BLAS, refit', \
     '' using (row('instances','billboard','1 (instance)','refit') ? column(4) : NaN):(column(24)) w lp pt 5 title 'instance per particle, TLAS refit', \
     '' using (row('aabbs','billboard','all','rebuild') ? column(4) : NaN):(column(24)) w lp pt 9 title 'one BLAS of procedural boxes', \
     '' using (row('aabbs','billboard','all','refit') ? column(4) : NaN):(column(24)) w lp pt 8 title 'one BLAS of procedural boxes, refit', \
     '' using (row('clusters','sphere','all','rebuild') ? column(4) : NaN):(column(24)) w lp pt 11 title 'one BLAS of built-in spheres', \
     '' using (row('clusters','sphere','all','refit') ? column(4) : NaN):(column(24)) w lp pt 10 title 'one BLAS of built-in spheres, refit'
unset multiplot
