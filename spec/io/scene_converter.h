// The scene converter behind ConvertScene (scene_convert.h), private to
// spec/io: one object per scene message, its member functions defined in
// one file per part of the scene, so a model kind's checks read (and change)
// apart from the others':
//   scene_convert.cc            the scene: model dispatch, effects, time grid, integrator
//   scene_convert_values.cc     parameters and expressions, numbers, vectors, directions, sections
//   scene_convert_lumped.cc     `lumped`
//   scene_convert_linkage.cc    `linkage`
//   scene_convert_multibody.cc  `multibody`, and its outputs
//   scene_convert_external.cc   `external`
//   scene_convert_fmu.cc        `fmu`
//   scene_convert_spatial.cc    `spatial`, and its outputs
//   scene_convert_spatial_forces.cc  `spatial` loads, rotational springs, bushings and their outputs
//   scene_convert_outputs.cc    `outputs`, each checked against the model kind
// Problems go to `errors`; the scene Run() returns is meaningful only if
// none were added.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "mbopt/v1/scene.pb.h"
#include "spec/expression.h"
#include "spec/io/locator.h"
#include "spec/scene.h"
#include "spec/units.h"

namespace mbopt::spec::io {

class SceneConverter {
 public:
  SceneConverter(const v1::Scene& message, const Where& where, Errors* errors)
      : msg_(message), where_(where), errors_(*errors) {}

  Scene Run();

 private:
  // ---------------------------------------------- scene_convert.cc --
  void ConvertEffects();
  void ConvertGrid();
  void ConvertIntegrator();

  // --------------------------------------- scene_convert_values.cc --
  void ConvertParameters();
  // The names of a scene's expressions: its parameters, those written as
  // `expr` standing for their expressions.
  Expression::Names ParameterNames();
  // Parses parameter i's `expr` once, after those it reads. A parameter met
  // again while its own expression is being read closes a cycle, refused
  // with the cycle's names.
  absl::Status ResolveParameter(int i);
  // A Number field `field` of the message at `w`; `present` says whether the
  // field was given. Absent: `fallback` if it is set, else an error.
  Number Num(const Where& w, const std::string& field, bool present, const v1::Number& n,
             Dimension dimension, std::optional<double> fallback = std::nullopt);
  double Default(const Number& n) const { return n.Resolve(scene_.DefaultParameterValues()); }
  void RequirePositive(const Where& w, const std::string& field, const Number& n);
  void RequireNotNegative(const Where& w, const std::string& field, const Number& n);
  Vec2 Vec(const Where& w, const std::string& field, bool present, const v1::Vector2& v,
           Dimension dimension);
  // A fixed unit direction: literal numbers, not zero; normalized here.
  void Direction(const Where& w, const std::string& field, bool present, const v1::Vector2& v,
                 double* dx, double* dy);
  // A beam cross-section (linkage links and multibody flexible links).
  Section ConvertSection(const Where& sw, const v1::Section& s);

  // --------------------------------------- scene_convert_lumped.cc --
  LumpedModel ConvertLumped(const v1::LumpedModel& m, const Where& w);
  Attachment Attach(const Where& w, const std::string& field, bool present, const v1::Attachment& a,
                    const std::map<std::string, int>& bodies,
                    const std::map<std::string, int>& inputs);

  // -------------------------------------- scene_convert_linkage.cc --
  LinkageModel ConvertLinkage(const v1::LinkageModel& m, const Where& w);

  // ------------------------------------ scene_convert_multibody.cc --
  // "body.marker" or "ground.marker" to a marker reference.
  MarkerRef Marker(const Where& w, const std::string& field, const std::string& ref);
  static std::vector<std::string> Names(const std::map<std::string, int>& table);
  std::vector<LinkPoint> Markers(const Where& w, const std::string& field,
                                 const google::protobuf::RepeatedPtrField<v1::Marker>& markers);
  int MultibodyJointIndex(const Where& w, const std::string& field, const std::string& name);
  MultibodyModel ConvertMultibody(const v1::MultibodyModel& m, const Where& w);
  void Harmonic(const Where& pw, const v1::HarmonicProfile& h, MultibodyDriver* out);
  // A table that must cover the motion, from 0 to the time grid's end.
  void Tabulated(const Where& pw, const v1::TabulatedProfile& t, MultibodyDriver* out);
  // The optional time factor of a point force or a torque.
  template <class Message>
  std::optional<TimeFactor> Factor(const Where& w, const Message& m);
  // A table of at least two finite points, abscissae strictly increasing.
  bool CheckTable(const Where& w, const std::string& x_field, const std::string& y_field, const std::vector<double>& x,
                  const std::vector<double>& y);
  MultibodyOutput MultibodyOutputOf(const v1::Output& o, const Where& ow);

  // -------------------------------------- scene_convert_external.cc --
  ExternalModel ConvertExternal(const v1::ExternalModel& m, const Where& w);
  static bool IsDriverName(const std::string& name);

  // ------------------------------------------- scene_convert_fmu.cc --
  FmuModel ConvertFmu(const v1::FmuModel& m, const Where& w);

  // -------------------------------------- scene_convert_spatial.cc --
  Vec3 Vec3Of(const Where& w, const std::string& field, bool present, const v1::Vector3& v, Dimension dimension);
  Orientation OrientationOf(const Where& w, const std::string& field, bool present, const v1::Orientation& o);
  std::vector<SpatialMarker> SpatialMarkers(const Where& w, const std::string& field,
                                            const google::protobuf::RepeatedPtrField<v1::SpatialMarker>& markers);
  // "body.marker" or "ground.marker" of the spatial model.
  MarkerRef SpatialMarkerOf(const Where& w, const std::string& field, const std::string& ref);
  int SpatialJointIndex(const Where& w, const std::string& field, const std::string& name);
  SpatialModel ConvertSpatial(const v1::SpatialModel& m, const Where& w);
  // Refuses rates, accelerations and kinetic energy in a static analysis.
  SpatialOutput SpatialOutputOf(const v1::Output& o, const Where& ow);
  SpatialOutput SpatialQuantityOf(const v1::Output& o, const Where& ow);

  // --------------------------------- scene_convert_spatial_forces.cc --
  // Point forces, torques, rotational springs and bushings into spatial_
  // (after its bodies and joints).
  void ConvertSpatialForces(const v1::SpatialModel& m, const Where& w);
  template <class Message>
  std::optional<TimeFactor> SpatialLoadFactor(const Where& w, const Message& m);
  // The outputs of force elements and multipliers: false for another kind.
  bool SpatialForceOutputOf(const v1::Output& o, const Where& ow, SpatialOutput* out);

  // --------------------------------------- scene_convert_outputs.cc --
  void ConvertOutputs();
  void ResolvePoint(const Where& w, const std::string& name, PointPositionOutput* k);

  const v1::Scene& msg_;
  const Where& where_;
  MultibodyModel multibody_;
  std::map<std::string, int> multibody_bodies_, multibody_joints_, multibody_springs_, multibody_inputs_,
      multibody_links_;
  Errors& errors_;
  Scene scene_;
  std::vector<Dimension> units_;  // per parameter
  enum class ResolveState { kUnresolved, kResolving, kResolved, kFailed };
  std::vector<ResolveState> resolve_state_;  // per parameter, for those written as `expr`
  std::vector<int> resolving_;               // the chain being resolved, for naming a cycle
  bool cycle_reported_ = false;
  std::map<std::string, int> lumped_bodies_, lumped_elements_;
  std::map<std::string, int> linkage_links_, linkage_joints_;
  SpatialModel spatial_;
  std::map<std::string, int> spatial_bodies_, spatial_joints_, spatial_springs_;
  std::map<std::string, int> spatial_rotational_springs_, spatial_bushings_;
};

}  // namespace mbopt::spec::io
