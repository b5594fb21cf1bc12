// Uses the installed core: one body falling freely has shaking force m*a.
#include <mechbal/mechbal.hpp>
#include <cmath>
#include <cstdio>

int main() {
  mechbal::RigidBody body;
  body.mass = 2.0;
  body.inertia_body = mechbal::Mat3::Identity() * 0.1;
  mechbal::BodyState state;
  state.com_acceleration = mechbal::Vec3(0.0, 0.0, -9.81);
  mechbal::ShakingWrench w;
  const mechbal::Status s = mechbal::shaking_wrench(&body, &state, 1, w);
  std::printf("mechbal %s: status %s, force z %.3f N\n", MECHBAL_VERSION, mechbal::status_name(s),
              w.force.z());
  return (s == mechbal::Status::ok && std::abs(w.force.z() + 19.62) < 1e-12) ? 0 : 1;
}
