// A downstream project using the scene component from the installed package: one sampled ARR
// scene with its instructions, drawn from the installed language data files.
#include <cstdio>

#include <manisoft/scene/scene_sampler.hpp>

int main() {
  manisoft::scene::SceneSampler sampler;
  manisoft::scene::SampleRequest q;
  q.task = manisoft::scene::Task::arr;
  q.setting = manisoft::scene::Setting::randomized;
  const auto s = sampler.sample(q);
  std::printf("%zu objects, %zu obstacles, %zu + %zu instructions; canonical: %s\n", s.objects.size(), s.obstacles.size(),
              s.instructions_seen.size(), s.instructions_unseen.size(), s.instruction.c_str());
  return s.instruction.empty() || s.instructions_seen.empty() ? 1 : 0;
}
