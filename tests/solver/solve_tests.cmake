# igi_solver: igi::Solve on real photographs (shared data, real/diligent_ball).
igi_add_test(diligent_solve_test SOURCES diligent_solve_test.cpp DEPS igi_solver)
# The paper stage's gathering: glossy surfaces pass on their specular reflection of the room
# (a 2 m room, one 64x48 photo rendered at 256 paths per pixel, two solves; about 10 s).
igi_add_test(solve_gather_test SOURCES solve_gather_test.cpp DEPS igi_solver)
# Stage 2's joint albedo update against the independent refit: one round from albedos 5 % too
# high in a bright closed room (SolverState directly; a few seconds).
igi_add_test(solve_refine_test SOURCES solve_refine_test.cpp DEPS igi_solver)
# The fit samples' draw is keyed by photo and pixel: one photo's changed pixels leave another
# photo's draw as it was (SolverState::Prepare twice on the 2 m room; a few seconds).
igi_add_test(solve_fit_samples_test SOURCES solve_fit_samples_test.cpp DEPS igi_solver)
# Observations drawn to a budget at collection, and the memory plan's refusal (the 2 m room with a
# glossy floor, three Prepares; a few seconds).
igi_add_test(observation_draw_test SOURCES observation_draw_test.cpp DEPS igi_solver)
# The solve's data and the stages that are functions of them alone (the fit samples' draw, the
# specular terms, the smoothing, the material estimate) on hand-made observations; instant.
igi_add_test(solve_state_test SOURCES solve_state_test.cpp DEPS igi_solver)
