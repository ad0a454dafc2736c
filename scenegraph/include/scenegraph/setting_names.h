// setting_names.h - one name table per settings enum, the only place where their names are
// spelled. Each entry holds the value, its name (written to and read from the command line and
// the JSON file), the label the UI shows and one line of help (CLI help, UI tooltips). Inputs
// also accept a few older spellings (aliases); outputs always use the entry's name.
//
// Adding a value: add it to the enum and to its table in setting_names.cpp; the panels, the CLI
// (choices, help, errors) and the JSON reader/writer pick it up.
#pragma once

#include "scenegraph/light.h"
#include "scenegraph/material.h"
#include "scenegraph/mesh.h"
#include "scenegraph/projection.h"
#include "scenegraph/settings.h"
#include "scenegraph/shapes.h"

#include <span>
#include <string>
#include <string_view>

namespace sg {

template <class E>
struct NamedValue {
    E value;
    std::string_view name;    // command line and JSON spelling
    std::string_view label;   // shown in the UI
    std::string_view help;    // one line
};

// An extra spelling accepted on input only (older files, habits); never written.
template <class E>
struct NameAlias {
    std::string_view name;
    E value;
};

template <class E>
struct NameTable {
    std::span<const NamedValue<E>> entries;
    std::span<const NameAlias<E>> aliases = {};

    const NamedValue<E>* find(const E& v) const {
        for (const auto& e : entries)
            if (e.value == v) return &e;
        return nullptr;
    }
    // By name or alias; nullptr when the name is not one of them.
    const NamedValue<E>* find(std::string_view name) const {
        for (const auto& e : entries)
            if (e.name == name) return &e;
        for (const auto& a : aliases)
            if (a.name == name) return find(a.value);
        return nullptr;
    }
    // The names (not the aliases) in table order: "off, linear, exp, exp2".
    std::string list(std::string_view separator = ", ") const {
        std::string out;
        for (const auto& e : entries) {
            if (!out.empty()) out += separator;
            out += e.name;
        }
        return out;
    }
};

// An anti-aliasing choice: the mode and its rate (0 for none, whose rate is kept as it was).
struct AAChoice {
    AAMode mode = AAMode::None;
    int rate = 0;
    bool operator==(const AAChoice&) const = default;
};
AAChoice aaChoice(const RenderSettings& s);

// Oblique projection presets (the command line accepts them as --projection values).
enum class ObliquePreset { Cavalier, Cabinet };
Projection obliquePreset(ObliquePreset p);

// Axonometric presets, also --projection values: isometric. As a projection it is orthographic;
// the command line (--projection isometric) and View > Axis view > Isometric also turn the camera
// to look along the isometric direction (projection.h).
enum class AxonometricPreset { Isometric };

template <class E>
const NameTable<E>& nameTable();
template <>
const NameTable<ShadingModel>& nameTable<ShadingModel>();
template <>
const NameTable<ReflectionModel>& nameTable<ReflectionModel>();
template <>
const NameTable<FogMode>& nameTable<FogMode>();
template <>
const NameTable<AAChoice>& nameTable<AAChoice>();
template <>
const NameTable<ProjectionType>& nameTable<ProjectionType>();
template <>
const NameTable<ObliquePreset>& nameTable<ObliquePreset>();
template <>
const NameTable<AxonometricPreset>& nameTable<AxonometricPreset>();
template <>
const NameTable<LightType>& nameTable<LightType>();
template <>
const NameTable<CullMode>& nameTable<CullMode>();
template <>
const NameTable<ToneMapping>& nameTable<ToneMapping>();
template <>
const NameTable<ShadowFilter>& nameTable<ShadowFilter>();
template <>
const NameTable<AlphaMode>& nameTable<AlphaMode>();
template <>
const NameTable<WrapMode>& nameTable<WrapMode>();
template <>
const NameTable<FilterMode>& nameTable<FilterMode>();
template <>
const NameTable<ImplicitType>& nameTable<ImplicitType>();
template <>
const NameTable<CsgOp>& nameTable<CsgOp>();
template <>
const NameTable<ParametricType>& nameTable<ParametricType>();

// The name of a value ("?" when it is not in the table) and the value of a name or alias.
template <class E>
std::string_view nameOf(const E& v) {
    const NamedValue<E>* e = nameTable<E>().find(v);
    return e ? e->name : std::string_view("?");
}
template <class E>
bool parseName(std::string_view name, E& out) {
    const NamedValue<E>* e = nameTable<E>().find(name);
    if (e) out = e->value;
    return e != nullptr;
}
template <class E>
std::string nameList(std::string_view separator = ", ") {
    return nameTable<E>().list(separator);
}

}   // namespace sg
