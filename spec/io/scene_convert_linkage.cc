// A `linkage` model: joints, links (rigid or flexible) and the driver.
#include "spec/io/scene_converter.h"

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "spec/io/declared_name.h"
#include "spec/limits.h"

namespace mbopt::spec::io {

LinkageModel SceneConverter::ConvertLinkage(const v1::LinkageModel& m, const Where& w) {
  LinkageModel out;
  std::map<std::string, int> joints;
  for (int i = 0; i < m.joints_size(); ++i) {
    const v1::Joint& j = m.joints(i);
    const Where jw = w.Child("joints", i);
    Joint joint;
    joint.name = j.name();
    joint.ground = j.ground();
    CheckDeclaredName(jw, j.name(), joints.emplace(j.name(), i).second,
                      {.missing = "a joint needs a name", .duplicate = "joint name"}, &errors_);
    if (!j.has_position_m())
      errors_.Add(jw, "position_m", "missing: expected the joint's position");
    joint.position_m =
        Vec(jw, "position_m", j.has_position_m(), j.position_m(), Dimension::kLength);
    out.joints.push_back(std::move(joint));
  }
  auto joint_index = [&](const Where& at, const std::string& field, const std::string& name) {
    auto it = joints.find(name);
    if (it == joints.end()) {
      errors_.Add(at, field, absl::StrCat("unknown joint \"", name, "\""));
      return -1;
    }
    return it->second;
  };
  std::map<std::string, int> links;
  for (int i = 0; i < m.links_size(); ++i) {
    const v1::Link& l = m.links(i);
    const Where lw = w.Child("links", i);
    Link link;
    link.name = l.name();
    CheckDeclaredName(lw, l.name(), links.emplace(l.name(), i).second,
                      {.missing = "a link needs a name", .duplicate = "link name"}, &errors_);
    link.joint_a = joint_index(lw, "joint_a", l.joint_a());
    link.joint_b = joint_index(lw, "joint_b", l.joint_b());
    if (link.joint_a >= 0 && link.joint_a == link.joint_b) {
      errors_.Add(lw, "joint_b", "a link needs two different joints");
    }
    if (l.has_length_m()) {
      link.length_m = Num(lw, "length_m", true, l.length_m(), Dimension::kLength);
      RequirePositive(lw, "length_m", *link.length_m);
    }
    if (l.has_section()) link.section = ConvertSection(lw.Child("section"), l.section());
    if (l.has_flexible()) {
      if (l.flexible().elements() < 1 || l.flexible().elements() > kMaxLinkageFlexibleElements) {
        errors_.Add(lw.Child("flexible"), "elements",
                    absl::StrCat("a flexible link needs 1 to ", kMaxLinkageFlexibleElements, " elements, got ",
                                 l.flexible().elements()));
      }
      if (!l.has_section()) {
        errors_.Add(lw, "section", "a flexible link needs a section");
      }
      link.flexible_elements = std::max(1, l.flexible().elements());
      link.rotary_inertia = l.flexible().rotary_inertia();
    }
    std::set<std::string> points;
    for (int p = 0; p < l.points_size(); ++p) {
      const Where pw = lw.Child("points", p);
      LinkPoint point;
      point.name = l.points(p).name();
      CheckDeclaredName(pw, point.name, points.insert(point.name).second,
                        {.missing = "a point needs a name", .duplicate = "point name"}, &errors_);
      point.position_m = Vec(pw, "position_m", l.points(p).has_position_m(),
                             l.points(p).position_m(), Dimension::kLength);
      link.points.push_back(std::move(point));
    }
    out.links.push_back(std::move(link));
  }
  if (m.links_size() == 0) errors_.Add(w, "links", "a linkage needs at least one link");
  if (!m.has_driver()) {
    errors_.Add(w, "driver",
                "missing: a linkage is driven at a prescribed speed, so it needs its driven link and pivot; to "
                "let the mechanism move freely (under its loads, gravity or springs, with no driver) write it as "
                "a `multibody` scene, whose drivers are optional (docs/scene.md)");
  } else {
    const Where dw = w.Child("driver");
    const v1::Driver& d = m.driver();
    auto it = links.find(d.link());
    if (it == links.end()) {
      errors_.Add(dw, "link", absl::StrCat("unknown link \"", d.link(), "\""));
    } else {
      out.driver.link = it->second;
    }
    out.driver.pivot_joint = joint_index(dw, "pivot_joint", d.pivot_joint());
    if (out.driver.link >= 0 && out.driver.pivot_joint >= 0) {
      const Link& link = out.links[static_cast<size_t>(out.driver.link)];
      if (link.joint_a != out.driver.pivot_joint && link.joint_b != out.driver.pivot_joint) {
        errors_.Add(dw, "pivot_joint",
                    absl::StrCat("joint \"", d.pivot_joint(), "\" is not an end of link \"",
                                 d.link(), "\""));
      } else if (!out.joints[static_cast<size_t>(out.driver.pivot_joint)].ground) {
        errors_.Add(
            dw, "pivot_joint",
            absl::StrCat("the driver's pivot \"", d.pivot_joint(), "\" must be a ground joint"));
      }
    }
    if (d.has_start_angle_rad()) {
      out.driver.start_angle_rad =
          Num(dw, "start_angle_rad", true, d.start_angle_rad(), Dimension::kAngle);
    }
    out.driver.angular_velocity_rad_per_s =
        Num(dw, "angular_velocity_rad_per_s", d.has_angular_velocity_rad_per_s(),
            d.angular_velocity_rad_per_s(), Dimension::kAngularVelocity);
  }
  switch (m.flexible_formulation()) {
    case v1::FLEXIBLE_FORMULATION_UNSPECIFIED:
    case v1::FLEXIBLE_FORMULATION_FLOATING_FRAME:
      out.flexible_formulation = FlexibleFormulation::kFloatingFrame;
      break;
    case v1::FLEXIBLE_FORMULATION_COROTATIONAL:
      out.flexible_formulation = FlexibleFormulation::kCorotational;
      break;
    default:
      errors_.Add(w, "flexible_formulation", "expected FLEXIBLE_FORMULATION_FLOATING_FRAME or "
                                             "FLEXIBLE_FORMULATION_COROTATIONAL");
  }
  if (m.flexible_formulation() != v1::FLEXIBLE_FORMULATION_UNSPECIFIED &&
      std::none_of(out.links.begin(), out.links.end(), [](const Link& l) { return l.flexible_elements > 0; })) {
    errors_.Add(w, "flexible_formulation",
                "chooses how flexible links are analysed, but no link is flexible: give the links a `flexible` "
                "block or remove the field");
  }
  linkage_links_ = links;
  linkage_joints_ = joints;
  return out;
}

}  // namespace mbopt::spec::io
