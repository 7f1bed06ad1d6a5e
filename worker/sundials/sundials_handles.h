// Owners of SUNDIALS 6 objects: the one RAII layer every integrator of the
// engine (CVODES, CVODES with its sensitivity module, IDAS) builds on, so that
// nothing leaks on any path and the order of destruction is right by
// construction: declare the owners in the order the objects are created
// (context, vectors, matrix, solvers, integrator memory) and C++ destroys
// them in reverse, integrator memory first, context last.
//
// Also the one way SUNDIALS' own error messages are captured: into a string
// that ends up in the caller's status or failure reason, never on stderr;
// and the one way a callback's exception is kept from crossing SUNDIALS' C
// frames (GuardCallback).
#pragma once

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nonlinearsolver.h>

#include <exception>
#include <memory>
#include <string>
#include <type_traits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace mbopt::sundials {

struct ContextFree {
  void operator()(SUNContext context) const { SUNContext_Free(&context); }
};
struct VectorFree {
  void operator()(N_Vector vector) const { N_VDestroy(vector); }
};
struct MatrixFree {
  void operator()(SUNMatrix matrix) const { SUNMatDestroy(matrix); }
};
struct LinearSolverFree {
  void operator()(SUNLinearSolver solver) const { SUNLinSolFree(solver); }
};
struct NonlinearSolverFree {
  void operator()(SUNNonlinearSolver solver) const { SUNNonlinSolFree(solver); }
};

using Context = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextFree>;
using Vector = std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorFree>;
using Matrix = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixFree>;
using LinearSolver = std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinearSolverFree>;
using NonlinearSolver = std::unique_ptr<std::remove_pointer_t<SUNNonlinearSolver>, NonlinearSolverFree>;

// An array of vectors (sensitivities), freed with its length.
class VectorArray {
 public:
  VectorArray() = default;
  VectorArray(N_Vector* vectors, int count) : vectors_(vectors), count_(count) {}
  ~VectorArray() { Reset(); }
  VectorArray(const VectorArray&) = delete;
  VectorArray& operator=(const VectorArray&) = delete;
  VectorArray(VectorArray&& other) noexcept : vectors_(other.vectors_), count_(other.count_) {
    other.vectors_ = nullptr;
  }
  VectorArray& operator=(VectorArray&& other) noexcept {
    if (this != &other) {
      Reset();
      vectors_ = other.vectors_;
      count_ = other.count_;
      other.vectors_ = nullptr;
    }
    return *this;
  }
  N_Vector* get() const { return vectors_; }
  N_Vector operator[](int k) const { return vectors_[k]; }
  explicit operator bool() const { return vectors_ != nullptr; }

 private:
  void Reset() {
    if (vectors_ != nullptr) N_VDestroyVectorArray(vectors_, count_);
    vectors_ = nullptr;
  }
  N_Vector* vectors_ = nullptr;
  int count_ = 0;
};

// Integrator memory (CVODE's or IDA's void*), freed by `free_memory`.
template <void (*free_memory)(void**)>
struct MemoryFree {
  void operator()(void* memory) const { free_memory(&memory); }
};
template <void (*free_memory)(void**)>
using Memory = std::unique_ptr<void, MemoryFree<free_memory>>;

inline Context MakeContext() {
  SUNContext context = nullptr;
  if (SUNContext_Create(nullptr, &context) != 0) return Context();
  return Context(context);
}

// An error handler for CVodeSetErrHandlerFn / IDASetErrHandlerFn: keeps the
// latest message in the std::string that `user_data` points to.
inline void CaptureMessage(int code, const char* module, const char* function, char* message, void* user_data) {
  *static_cast<std::string*>(user_data) =
      absl::StrFormat("%s %s (code %d): %s", module != nullptr ? module : "SUNDIALS",
                      function != nullptr ? function : "", code, message != nullptr ? message : "");
}

// Runs the body of a SUNDIALS callback (a C function: no exception may
// leave it). An exception becomes `*failure` ("NAME threw: what") and the
// return value `unrecoverable`, which SUNDIALS turns into a failed call whose
// reason the caller reads from `*failure`.
template <class Body>
int GuardCallback(std::string* failure, const char* name, Body&& body, int unrecoverable = -1) {
  try {
    return body();
  } catch (const std::exception& e) {
    *failure = absl::StrCat(name, " threw: ", e.what());
  } catch (...) {
    *failure = absl::StrCat(name, " threw a non-standard exception");
  }
  return unrecoverable;
}

}  // namespace mbopt::sundials
