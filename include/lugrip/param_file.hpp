// lugrip — reading a parameter file (optional target lugrip::yaml, on yaml-cpp): the contact
// parameters and, for a file written by identification, the observer they were identified with.
#pragma once

#include <string>

#include "lugrip/grasp_controller.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/params.hpp"
#include "lugrip/slip_control.hpp"

namespace lugrip {

//! What a parameter file holds.
struct ParameterFile {
  ContactParams params;          //!< the contact block (validated)
  bool has_observer = false;     //!< the file has an observer block
  ObserverSettings observer;     //!< defaults overridden by the observer block (validated)
  bool has_controller = false;   //!< the file has a controller block
  GraspControllerSettings controller;  //!< defaults overridden by the controller block (validated)
};

//! Reads a parameter YAML: the layout `lugrip params` and `lugrip identify` write (a `contact`
//! mapping whose fields are numbers or {value: ...} mappings; ".inf" allowed for k) or flat
//! fields, plus an optional `observer` mapping with the keywords of the Python Observer
//! (ObserverSettings fields, integrator and gain_mode by name, the CorSettings fields
//! f_n_min, force_limit, torque_limit, zero_force, zero_torque) and an optional `controller`
//! mapping of GraspControllerSettings fields by name (grasp_controller_fields: numbers, integers,
//! true/false). Other top-level keys (fit summary, standard errors) are ignored. Files over
//! 1 MiB are refused.
//! Throws std::invalid_argument "<path>: <field>: <problem>" naming the first bad field.
ParameterFile load_parameter_file(const std::string& path);

//! As load_parameter_file() from YAML text; `name` prefixes the messages.
ParameterFile parse_parameter_file(const std::string& text, const std::string& name = "<text>");

//! SlipControl settings for the file: its observer and controller blocks (or the defaults).
SlipControlSettings slip_control_settings(const ParameterFile& file);
//! The same with `controller` instead of the file's controller block.
SlipControlSettings slip_control_settings(const ParameterFile& file,
                                          const GraspControllerSettings& controller);

}  // namespace lugrip
