// Uses the installed core: one body falling freely has shaking force m*a; a one-joint URDF read
// through urdfdom (linked through the installed CMake package) has one coordinate.
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
  const mechbal::MechanismModel arm = mechbal::model_from_urdf_string(
      "<robot name='arm'><link name='base'/><link name='arm'><inertial><mass value='1'/>"
      "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link>"
      "<joint name='shoulder' type='continuous'><parent link='base'/><child link='arm'/></joint>"
      "</robot>");
  std::printf("URDF: %d coordinate(s), %d body(ies)\n", arm.dof(), arm.num_bodies());
  return (s == mechbal::Status::ok && std::abs(w.force.z() + 19.62) < 1e-12 && arm.dof() == 1 &&
          arm.num_bodies() == 1)
             ? 0
             : 1;
}
