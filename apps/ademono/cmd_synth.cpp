// `ademono synth`: renders a synthetic TUM RGB-D sequence with ground-truth poses, depth,
// moving-object masks and detections (see src/ademono/synth/generator.h and docs/synth.md).
#include <spdlog/spdlog.h>

#include <cstdint>
#include <iostream>
#include <stdexcept>
#include <string>

#include "ademono/core/error.h"
#include "ademono/synth/generator.h"
#include "command.h"

namespace {

struct SynthArgs {
  std::string scene = "office";
  std::string motion;
  size_t frames = 100;
  uint64_t seed = 0;
  int width = 0, height = 0;
  int persons = 2;
  double noise = 0.0;
  double blur = 0.0;
  std::string actor_photos;  // empty: procedural actors
  std::string out;
};

int RunSynth(const SynthArgs& args) {
  ademono::synth::GeneratorOptions options;
  options.scene.scene = args.scene;
  if (!args.motion.empty()) {
    try {
      options.scene.motion = ademono::synth::ParseMotionKind(args.motion);
    } catch (const std::invalid_argument& e) {
      throw ademono::InputError(e.what());
    }
  }
  options.scene.frames = args.frames;
  options.scene.seed = args.seed;
  options.scene.width = args.width;
  options.scene.height = args.height;
  options.scene.persons = args.persons;
  options.noise_sigma = args.noise;
  options.blur_px = args.blur;
  options.scene.actor_photos = args.actor_photos;
  const size_t every = std::max<size_t>(1, args.frames / 10);
  const auto summary =
      ademono::synth::GenerateSequence(options, args.out, [&](size_t done, size_t total) {
        if (done % every == 0 || done == total) spdlog::info("synth: {}/{} frames", done, total);
      });
  std::cout << "wrote " << summary.frames << " frames of '" << args.scene << "' to " << args.out
            << " (" << summary.detections << " ground-truth boxes, moving objects cover "
            << 100.0 * summary.moving_pixel_fraction << "% of pixels; rendering "
            << summary.frames / std::max(1e-9, summary.seconds_rendering) << " frames/s, total "
            << summary.seconds_total << " s)\n";
  return 0;
}

const bool kRegistered = ademono::cli::RegisterCommand(
    "synth", "Render a synthetic RGB-D sequence (office or street) with ground truth",
    [](CLI::App& app) -> ademono::cli::Runner {
      auto args = std::make_shared<SynthArgs>();
      app.add_option("--scene", args->scene, "office | street")->capture_default_str();
      app.add_option("--motion", args->motion,
                     "xyz | halfsphere | rpy | static | forward | loop (default: xyz for office, "
                     "forward for street)");
      app.add_option("--frames", args->frames, "number of frames")->capture_default_str();
      app.add_option("--seed", args->seed, "random seed (textures, actors, jitter)")
          ->capture_default_str();
      app.add_option("--width", args->width, "image width (default: the scene's)");
      app.add_option("--height", args->height, "image height (default: the scene's)");
      app.add_option("--persons", args->persons, "office: walking persons, 1..3")
          ->capture_default_str();
      app.add_option("--noise", args->noise, "Gaussian image noise sigma, grey levels")
          ->capture_default_str();
      app.add_option("--blur", args->blur, "motion blur length in pixels")->capture_default_str();
      app.add_option("--actor-photos", args->actor_photos,
                     "photo-textured actors cut from the persons and cars of DIR (photos plus "
                     "expected_detections.json; given without DIR: ../shared/images), and "
                     "movers of no COCO class; off by default")
          ->expected(0, 1)
          ->default_str("../shared/images");
      app.add_option("--out", args->out, "output folder (must not exist or be empty)")->required();
      return [args] { return RunSynth(*args); };
    });

}  // namespace
