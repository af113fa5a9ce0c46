#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/tuple.h>
#include <cmath>
#include <cstring>
namespace nb = nanobind;
using Pose = nb::ndarray<const double, nb::numpy, nb::shape<4, 4>, nb::c_contig, nb::device::cpu>;
using Vec = nb::ndarray<nb::numpy, double, nb::shape<7>>;
struct Solution {
    nb::object q; bool ok; nb::str status; nb::object configuration;
    double position_error, orientation_error; long iterations; bool within_limits;
};
static nb::object configuration_type;
// The same work as capi_stub.solve_pose, idiomatic nanobind: typed arguments, a bound result class.
static nb::object solve_pose(Pose T, nb::handle c) {
    if (!nb::isinstance(c, configuration_type)) return nb::none();
    nb::object sg = c.attr("signs"), rd = c.attr("redundancy");
    nb::tuple s = nb::borrow<nb::tuple>(sg), r = nb::borrow<nb::tuple>(rd);
    if (s.size() != 3 || r.size() != 1) return nb::none();
    long signs[3]; double red = nb::cast<double>(r[0]);
    for (int i = 0; i < 3; i++) { signs[i] = nb::cast<long>(s[i]); if (signs[i] != 1 && signs[i] != -1) return nb::none(); }
    if (!std::isfinite(red)) return nb::none();
    double Tc[16]; std::memcpy(Tc, T.data(), 128);
    double *q = new double[7];
    { nb::gil_scoped_release g; for (int i = 0; i < 7; i++) q[i] = Tc[i] * signs[i % 3] + red; }
    nb::capsule owner(q, [](void *p) noexcept { delete[] (double *)p; });
    return nb::cast(Solution{nb::cast(Vec(q, {7}, owner)), true, nb::str("ok"), nb::borrow(c), 0.0, 0.0, 3, true});
}
NB_MODULE(nb_stub, m) {
    nb::set_leak_warnings(false);  // (the stub keeps the configuration type to the end)
    nb::class_<Solution>(m, "Solution")
        .def_ro("q", &Solution::q).def_ro("ok", &Solution::ok).def_ro("status", &Solution::status)
        .def_ro("configuration", &Solution::configuration).def_ro("position_error", &Solution::position_error)
        .def_ro("orientation_error", &Solution::orientation_error).def_ro("iterations", &Solution::iterations)
        .def_ro("within_limits", &Solution::within_limits);
    m.def("set_type", [](nb::object t) { configuration_type = t; });
    m.def("solve_pose", &solve_pose);
}
