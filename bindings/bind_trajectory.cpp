#include <pybind11/eigen.h>
#include <pybind11/numpy.h>

#include <cmath>
#include <string>

#include "array_checks.hpp"
#include "bindings.hpp"
#include "mechbal/control/trajectory.hpp"

namespace py = pybind11;

namespace mechbal::pyb {

namespace {

void bind_trajectory(pybind11::module_& m) {
  py::enum_<TimeLaw>(m, "TimeLaw")
      .value("quintic", TimeLaw::quintic)
      .value("cubic", TimeLaw::cubic);

  py::class_<RestToRestTrajectory>(m, "RestToRestTrajectory",
                                   R"doc(Rest-to-rest motion q0 -> q1 in T seconds along a quintic
or minimum-energy cubic law (Arakelian et al. 2011, eqs 10-13).)doc")
      .def(py::init([](const Array& start, const Array& end, double duration, TimeLaw law) {
             return RestToRestTrajectory(vector_arg(start, "start", -1), vector_arg(end, "end", -1),
                                         duration, law);
           }),
           py::arg("start"), py::arg("end"), py::arg("duration"), py::arg("law") = TimeLaw::quintic)
      .def_property_readonly("duration", &RestToRestTrajectory::duration)
      .def_property_readonly("size", &RestToRestTrajectory::size)
      .def_property_readonly("law", &RestToRestTrajectory::law)
      .def("evaluate",
           [](const RestToRestTrajectory& t, double time) {
             if (!std::isfinite(time)) throw py::value_error("t must be finite, got " + std::to_string(time));
             Eigen::VectorXd q(t.size()), qd(t.size()), qdd(t.size());
             t.evaluate(time, q, qd, qdd);
             return py::make_tuple(q, qd, qdd);
           },
           py::arg("t"), "(q, v, a) at time t")
      .def("evaluate_batch",
           [](const RestToRestTrajectory& t, const Array& times) {
             require_shape(times, "times", {-1});
             require_finite(times, "times");
             const auto N = times.shape(0);
             OutArray q = make_array({N, t.size()}), qd = make_array({N, t.size()}),
                      qdd = make_array({N, t.size()});
             t.evaluate_batch(times.data(), N, q.mutable_data(), qd.mutable_data(),
                              qdd.mutable_data());
             return py::make_tuple(q, qd, qdd);
           },
           py::arg("times"), "(q, v, a), each (N, size), at the N given times");
}

}  // namespace

MECHBAL_REGISTER_BINDINGS(10, trajectory, bind_trajectory);

}  // namespace mechbal::pyb
