// Loads a scene through the installed igi package and prints its size:
//   igi_consumer scene.json  ->  "materials 8 lights 2 cameras 3 triangles 36"
#include <cstdio>
#include <exception>

#include "recon/scene.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  try {
    igi::recon::SceneLoadOptions options;
    options.check_images = false;
    const igi::recon::Scene scene = igi::recon::LoadScene(argv[1], options);
    std::printf("materials %zu lights %zu cameras %zu triangles %zu\n", scene.materials.size(),
                scene.lights.size(), scene.cameras.size(), scene.mesh.num_triangles());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
