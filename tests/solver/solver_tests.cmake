# igi_solver: albedo-map atlases (generated UV charts) and albedo maps.
igi_add_test(uv_charts_test SOURCES uv_charts_test.cpp DEPS igi_solver)
igi_add_test(albedo_map_test SOURCES albedo_map_test.cpp DEPS igi_solver)
igi_add_test(scene_scale_test SOURCES scene_scale_test.cpp DEPS igi_solver igi_render)
igi_add_test(albedo_map_stage_test SOURCES albedo_map_stage_test.cpp DEPS igi_solver)
igi_add_test(fit_stage_test SOURCES fit_stage_test.cpp DEPS igi_solver)
igi_add_test(held_out_albedo_test SOURCES held_out_albedo_test.cpp DEPS igi_solver)
