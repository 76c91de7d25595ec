// A first C++ program on an installed partsim: a box dropped on the ground comes to rest.
// Build it against an install (see docs/install.md):
//   cmake -S . -B build -DCMAKE_PREFIX_PATH=PREFIX && cmake --build build && ./build/hello
#include <cstdio>

#include "partsim/physics/scene.h"

int main() {
  partsim::Scene scene;  // 500 Hz, gravity -9.81 m/s^2 along z
  scene.AddGround(0.0);

  // a 0.2 m box (half sizes in metres) dropped from 0.5 m
  partsim::CollisionShape shape;
  shape.half_size = Eigen::Vector3d(0.1, 0.1, 0.1);
  partsim::ActorDesc desc;
  desc.name = "box";
  desc.pose = partsim::Pose(Eigen::Vector3d(0, 0, 0.5));
  desc.collisions.push_back(shape);
  partsim::Actor box = scene.AddActor(desc);

  scene.Step(1000);  // 2 s
  std::printf("%s rests at z = %.3f m after %.1f s\n", box.GetName().c_str(), box.GetPose().p.z(),
              scene.GetTime());
  return box.GetPose().p.z() > 0.09 && box.GetPose().p.z() < 0.11 ? 0 : 1;
}
