# igi_solver: igi::Solve on real photographs (shared data, real/diligent_ball).
igi_add_test(diligent_solve_test SOURCES diligent_solve_test.cpp DEPS igi_solver)
