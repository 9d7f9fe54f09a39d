// Compiled entries for Exudyn's force user functions (gearbody.engine.compiled_path).
//
// Exudyn stores ObjectGenericODE2.forceUserFunction as a
//     std::function<StdVector(const MainSystem&, Real, Index, StdVector, StdVector)>
// filled by pybind11's std::function caster. When the Python object given is a stateless C++ function
// exported by a pybind11 module with exactly that function type, pybind11 takes its function pointer and
// Exudyn calls it from C++: no Python call per evaluation. Each exported entry owns one slot; a slot
// lists terms, each a numba cfunc (the force laws of gearbody.physics, written once in numba) and the
// packed parameters it reads, added into the item's forces in order. Every CHECK-th call of a watched
// slot calls the run's Python watchdog (divergence, wall time, stall, memory, Ctrl-C, progress), the same
// cadence as the Python path.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace py = pybind11;

// Exudyn's type name, so that the function type matches Exudyn's user-function type; never touched
// (its address only tells which system calls).
class MainSystem {};

typedef void (*Kernel)(double t, int64_t n, const double *q, const double *q_t, double *f, const double *P);

struct Term {
    Kernel kernel;
    const double *parameters;
};

struct Slot {
    bool used = false;
    int size = 0;  // coordinates of the item
    std::vector<Term> terms;
    const void *owner = nullptr;  // the MainSystem that called first
    unsigned long long calls = 0;
    // the run's watchdog: check(t, speed) every `every` calls, speed = q_t[speed_index]
    PyObject *check = nullptr;  // a strong reference (released by `release`, never at exit)
    long long every = 0;
    int speed_index = 0;
};

constexpr int SLOTS = 512;
static Slot slots[SLOTS];

static std::vector<double> evaluate(Slot &s, const void *owner, double t, const std::vector<double> &q,
                                    const std::vector<double> &q_t) {
    if (s.owner != owner) {
        if (s.owner != nullptr || !s.used)
            throw std::runtime_error("gearbody: a compiled force item was called by a system it does not belong to");
        s.owner = owner;
    }
    if ((int)q.size() != s.size || (int)q_t.size() != s.size)
        throw std::runtime_error("gearbody: a compiled force item got the wrong number of coordinates");
    s.calls += 1;
    if (s.every > 0 && s.calls % s.every == 0) {
        py::handle(s.check)(t, q_t[s.speed_index]);  // raises error_already_set: Exudyn stops the run
    }
    std::vector<double> f(s.size, 0.0);
    for (const Term &term : s.terms) term.kernel(t, s.size, q.data(), q_t.data(), f.data(), term.parameters);
    return f;
}

template <int K>
std::vector<double> entry(const MainSystem &mbs, double t, int item, std::vector<double> q,
                          std::vector<double> q_t) {
    (void)item;
    return evaluate(slots[K], &mbs, t, q, q_t);
}

static Slot &slot_at(int k) {
    if (k < 0 || k >= SLOTS) throw std::out_of_range("slot " + std::to_string(k) + " outside 0.." + std::to_string(SLOTS - 1));
    return slots[k];
}

static void clear(Slot &s) {
    Py_XDECREF(s.check);
    s = Slot();
}

static int acquire() {
    for (int k = 0; k < SLOTS; ++k)
        if (!slots[k].used) {
            clear(slots[k]);
            slots[k].used = true;
            return k;
        }
    return -1;
}

// Counts calls that came through Python (pybind11's dispatcher constructs it; a call Exudyn makes through
// the unwrapped function pointer does not): the probe's proof that no evaluation went through Python.
static unsigned long long python_calls = 0;
struct PythonCall {
    PythonCall() { ++python_calls; }
};

static void assign(int k, int size, const std::vector<std::uintptr_t> &kernels,
                   const std::vector<std::uintptr_t> &parameters) {
    Slot &s = slot_at(k);
    if (kernels.size() != parameters.size()) throw std::invalid_argument("one parameter address per kernel");
    s.size = size;
    s.terms.clear();
    for (size_t i = 0; i < kernels.size(); ++i)
        s.terms.push_back({reinterpret_cast<Kernel>(kernels[i]), reinterpret_cast<const double *>(parameters[i])});
}

static void watch(int k, py::object check, long long every, int speed_index) {
    Slot &s = slot_at(k);
    if (speed_index < 0 || speed_index >= s.size) throw std::out_of_range("speed index outside the item");
    PyObject *previous = s.check;
    s.check = check.release().ptr();
    Py_XDECREF(previous);
    s.every = every;
    s.speed_index = speed_index;
}

static void release(int k) {
    clear(slot_at(k));
}

template <int... K>
static void define_entries(py::module_ &m, std::integer_sequence<int, K...>) {
    py::list entries;
    (entries.append(py::cpp_function(&entry<K>, py::name("compiled_force"), py::call_guard<PythonCall>())), ...);
    m.attr("entries") = entries;
}

PYBIND11_MODULE(_force_entry, m) {
    m.doc() = "Compiled entries for Exudyn's force user functions (gearbody.engine.compiled_path)";
    define_entries(m, std::make_integer_sequence<int, SLOTS>{});
    m.attr("SLOTS") = SLOTS;
    m.attr("ABI_VERSION") = 1;  // gearbody.engine.compiled_path.ABI_VERSION: the interface below
    m.def("acquire", &acquire, "A free slot (-1: none)");
    m.def("assign", &assign, py::arg("slot"), py::arg("size"), py::arg("kernels"), py::arg("parameters"),
          "Terms of a slot: cfunc addresses and the addresses of their float64 parameter arrays");
    m.def("watch", &watch, py::arg("slot"), py::arg("check"), py::arg("every"), py::arg("speed_index"),
          "Call check(t, q_t[speed_index]) every `every` calls");
    m.def("release", &release, py::arg("slot"));
    m.def("calls", [](int k) { return slot_at(k).calls; }, py::arg("slot"), "Evaluations of a slot, counted in C++");
    m.def("python_calls", []() { return python_calls; }, "Calls of any entry that came through Python");
    m.def("used", []() {
        int n = 0;
        for (const Slot &s : slots) n += s.used;
        return n;
    });
}
