// palpate inside a haptics application that owns its device loop (see
// doc/embedding.md). Build: link against palpate's layer libraries
// (doc/embedding.md); run: embed scene.prm
#include <palpate/base/environment.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/scene/scene.h>

#include <chrono>
#include <iostream>
#include <thread>

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv); // MPI and thread settings, first
  palpate::Interaction organ(
    palpate::Scene::read(argc > 1 ? argv[1] : "scene.prm"));

  organ.attach(); // contact: the engine computes the cloud around rest
  while (!organ.initial_cloud_complete())
    std::this_thread::sleep_for(std::chrono::milliseconds(10));

  // The host's 1 kHz device callback; here the "device" presses 10 mm down
  // in one second. force() never blocks, allocates or returns NaN.
  auto next = std::chrono::steady_clock::now();
  for (int tick = 0; tick <= 1000; ++tick)
    {
      const palpate::Utilities::Point3 hip{{0, 0, -1e-5 * tick}}; // m
      const palpate::Utilities::Point3 f = organ.force(hip);      // N
      if (tick % 250 == 0)
        std::cout << "t = " << tick / 1000. << " s, force (" << f[0] << ", "
                  << f[1] << ", " << f[2] << ") N\n";
      std::this_thread::sleep_until(next += std::chrono::milliseconds(1));
    }
  organ.detach();
  organ.poll_events(std::cout); // missing-data events, if any
  std::cout << "missing-data events: " << organ.summary().missing_events
            << "\n";
  return 0;
}
