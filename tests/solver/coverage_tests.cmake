# Highlight coverage (solver/inverse/highlight_coverage.h): which regions' highlights the photos show.
igi_add_test(highlight_coverage_test SOURCES highlight_coverage_test.cpp
             DEPS igi_solver igi_synth)
