#include "spec/responses.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace mbopt::spec {
namespace {

// Where one name of a response's expression takes its value at (series,
// instant) of the response.
struct Reader {
  int signal = -1;      // >= 0: a signal
  int parameter = -1;   // >= 0: a parameter
  bool time = false;
};

std::vector<Reader> ReadersOf(const Study& study, const Response& response) {
  std::vector<Reader> readers;
  for (int name : response.expression->parameters()) {
    Reader reader;
    if (name < study.num_signals()) {
      reader.signal = name;
    } else if (name < study.TimeNameIndex()) {
      reader.parameter = name - study.num_signals();
    } else {
      reader.time = true;
    }
    readers.push_back(reader);
  }
  return readers;
}

// The value of signal `signal` at the response's (series, instant): a
// one-series signal serves every series, a scalar every instant.
double SignalAt(const OutputShape& shape, const Series& series, int s, int i) {
  return series[static_cast<size_t>(shape.series == 1 ? 0 : s)][static_cast<size_t>(shape.instants == 1 ? 0 : i)];
}

// The expression's inputs at (s, i): signals, parameters and t.
void FillInputs(const Study& study, const StudyLayout& layout, const std::vector<Reader>& readers,
                const std::vector<const Series*>& signals, int s, int i, std::vector<double>* inputs) {
  for (size_t k = 0; k < readers.size(); ++k) {
    const Reader& reader = readers[k];
    if (reader.signal >= 0) {
      const size_t sig = static_cast<size_t>(reader.signal);
      (*inputs)[sig] = SignalAt(layout.outputs[sig], *signals[sig], s, i);
    } else if (reader.time) {
      (*inputs)[static_cast<size_t>(study.TimeNameIndex())] =
          layout.instants_s.empty() ? 0.0 : layout.instants_s[static_cast<size_t>(i)];
    }
  }
}

}  // namespace

absl::StatusOr<OutputShape> ResponseShape(const Study& study, int response, const std::vector<OutputShape>& shapes,
                                          int instants) {
  const Response& r = study.responses[static_cast<size_t>(response)];
  OutputShape shape;
  shape.series = 1;
  shape.series_labels = {r.name};
  shape.instants = 1;
  shape.scalar = true;
  for (const Reader& reader : ReadersOf(study, r)) {
    if (reader.time) {
      shape.instants = instants;
      shape.scalar = false;
    }
    if (reader.signal < 0) continue;
    const OutputShape& read = shapes[static_cast<size_t>(reader.signal)];
    if (!read.scalar) {
      shape.instants = instants;
      shape.scalar = false;
    }
    if (read.series == 1) continue;
    if (shape.series != 1 && shape.series != read.series) {
      return absl::InvalidArgumentError(absl::StrCat(
          "response \"", r.name, "\" reads \"", study.SignalName(reader.signal), "\" with ", read.series,
          " series and another signal with ", shape.series, "; signals read together need the same number of "
          "series, or one"));
    }
    shape.series = read.series;
    shape.series_labels = read.series_labels;
  }
  return shape;
}

void AppendResponses(const Study& study, const StudyLayout& layout, const std::vector<double>& parameter_values_si,
                     std::vector<Series>* storage, std::vector<const Series*>* signals) {
  storage->clear();
  storage->reserve(study.responses.size());  // `signals` points into it
  std::vector<double> inputs(static_cast<size_t>(study.TimeNameIndex()) + 1, 0.0);
  std::copy(parameter_values_si.begin(), parameter_values_si.end(),
            inputs.begin() + study.ParameterNameIndex(0));
  for (size_t r = 0; r < study.responses.size(); ++r) {
    const Response& response = study.responses[r];
    const std::vector<Reader> readers = ReadersOf(study, response);
    const OutputShape& shape = layout.outputs[static_cast<size_t>(study.num_case_signals()) + r];
    Series values(static_cast<size_t>(shape.series), std::vector<double>(static_cast<size_t>(shape.instants)));
    for (int s = 0; s < shape.series; ++s) {
      for (int i = 0; i < shape.instants; ++i) {
        FillInputs(study, layout, readers, *signals, s, i, &inputs);
        values[static_cast<size_t>(s)][static_cast<size_t>(i)] = response.expression->Evaluate(inputs);
      }
    }
    storage->push_back(std::move(values));
    signals->push_back(&storage->back());
  }
}

void AppendResponseDerivatives(const Study& study, const StudyLayout& layout,
                               const std::vector<double>& parameter_values_si,
                               const std::vector<const Series*>& signals, std::vector<std::vector<Series>>* storage,
                               std::vector<std::vector<const Series*>>* derivatives) {
  const size_t n = study.variables.size();
  storage->assign(n, {});
  for (auto& per_variable : *storage) per_variable.reserve(study.responses.size());
  // sets[i][p]: variable i sets parameter p (its own or through also_sets).
  std::vector<std::vector<bool>> sets(n, std::vector<bool>(study.scene.parameters.size(), false));
  for (size_t i = 0; i < n; ++i) {
    const DesignVariable& v = study.variables[i];
    sets[i][static_cast<size_t>(v.parameter)] = true;
    for (int also : v.also_sets) sets[i][static_cast<size_t>(also)] = true;
  }
  std::vector<double> inputs(static_cast<size_t>(study.TimeNameIndex()) + 1, 0.0);
  std::copy(parameter_values_si.begin(), parameter_values_si.end(),
            inputs.begin() + study.ParameterNameIndex(0));
  std::vector<double> partials;
  for (size_t r = 0; r < study.responses.size(); ++r) {
    const Response& response = study.responses[r];
    const std::vector<Reader> readers = ReadersOf(study, response);
    const OutputShape& shape = layout.outputs[static_cast<size_t>(study.num_case_signals()) + r];
    std::vector<Series> d(n, Series(static_cast<size_t>(shape.series),
                                    std::vector<double>(static_cast<size_t>(shape.instants), 0.0)));
    for (int s = 0; s < shape.series; ++s) {
      for (int t = 0; t < shape.instants; ++t) {
        FillInputs(study, layout, readers, signals, s, t, &inputs);
        response.expression->EvaluateWithPartials(inputs, &partials);
        for (size_t i = 0; i < n; ++i) {
          double sum = 0.0;
          for (size_t k = 0; k < readers.size(); ++k) {
            const Reader& reader = readers[k];
            if (reader.signal >= 0) {
              const size_t sig = static_cast<size_t>(reader.signal);
              const double ds = SignalAt(layout.outputs[sig], *(*derivatives)[i][sig], s, t);
              if (ds != 0.0) sum += partials[k] * ds;
            } else if (reader.parameter >= 0 && sets[i][static_cast<size_t>(reader.parameter)]) {
              sum += partials[k];
            }
          }
          d[i][static_cast<size_t>(s)][static_cast<size_t>(t)] = sum;
        }
      }
    }
    for (size_t i = 0; i < n; ++i) {
      (*storage)[i].push_back(std::move(d[i]));
      (*derivatives)[i].push_back(&(*storage)[i].back());
    }
  }
}

}  // namespace mbopt::spec
