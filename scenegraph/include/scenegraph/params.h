// params.h - one table for every value a user edits: the render settings, the camera's
// projection, a material, a light. Each row holds what every reader and writer of that value
// needs: its scene-JSON key, its command-line flag, the UI's label, one line of help, the UI
// section, its kind (bool, int, float, colour, choice), its valid range (inclusive), whether
// the UI slides it on a log scale, the renderer feature it needs to have an effect, how to get
// and set it, and when the UI shows it.
//
// Everything loops over these tables: validate() checks their ranges, the scene file's reader
// and writer (assets/src/scene_json.cpp), the command line's options and their application
// (app/cli.cpp), the panels' widgets (ui/src/panels), `set KEY VALUE` and the undo labels. So a
// UI range is a validation range by construction, and adding a setting is a field in its
// struct plus one row here (README, "How to add a setting").
//
// Keys: "fog.density" is member "density" of the object "fog" inside the owner's JSON object
// (the scene's "settings", a camera payload, a material, a light payload).
#pragma once

#include "scenegraph/light.h"
#include "scenegraph/material.h"
#include "scenegraph/projection.h"
#include "scenegraph/setting_names.h"
#include "scenegraph/settings.h"

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

namespace sg {

// Text: a free string (a file name, or one of a few words the row's help names).
enum class ParamKind : uint8_t { Bool, Int, Float, Color, Choice, Text };

// A parameter's value: bool, int, float, colour (linear RGB), a choice by its name or text.
using ParamValue = std::variant<bool, int, float, vec3, std::string>;

// A renderer feature a parameter needs to have any effect; renderers say which they have
// (rnd::hasFeature), and the UI marks a parameter the shown backend ignores.
enum class Feature : uint8_t { None, Shadows, ShadowMaps, ShadowRays, Reflections, Wireframe };

// One value of a Choice parameter (from the enum's name table, setting_names.h).
struct ParamChoice {
    std::string_view name, label, help;
};

template <class T>
struct Param {
    std::string_view key;       // scene-JSON key within T's object ("fog.density")
    std::string_view flag;      // command-line option without "--" ("" = none)
    std::string_view label;     // UI label ("" = not shown in the panels)
    std::string_view help;      // one line: CLI help, UI tooltip
    std::string_view section;   // UI group ("Fog")
    ParamKind kind = ParamKind::Float;
    double min = 0.0, max = 0.0;    // Int and Float: valid range, inclusive (Float: finite too)
    bool logScale = false;          // UI: logarithmic slider
    bool drag = false;              // UI: a drag field (open-ended ranges) instead of a slider
    bool radios = false;            // UI: a Choice as a row of radio buttons instead of a combo
    const char* format = nullptr;   // UI number format ("%.1f deg"); nullptr = ImGui's default
    Feature needs = Feature::None;
    ParamValue (*get)(const T&) = nullptr;
    // Sets a value of the param's kind (false for another kind or an unknown choice name);
    // ranges are checked by checkParams, not here.
    bool (*set)(T&, const ParamValue&) = nullptr;
    std::vector<ParamChoice> choices;    // Choice: the names in table order
    bool (*shown)(const T&) = nullptr;   // UI: whether the value matters now (nullptr = always)

    // Fluent helpers for the tables.
    Param range(double lo, double hi) const {
        Param p = *this;
        p.min = lo;
        p.max = hi;
        return p;
    }
    Param log() const {
        Param p = *this;
        p.logScale = true;
        return p;
    }
    Param dragged(const char* fmt = nullptr) const {
        Param p = *this;
        p.drag = true;
        p.format = fmt;
        return p;
    }
    Param asRadios() const {
        Param p = *this;
        p.radios = true;
        return p;
    }
    Param fmt(const char* f) const {
        Param p = *this;
        p.format = f;
        return p;
    }
    Param needing(Feature f) const {
        Param p = *this;
        p.needs = f;
        return p;
    }
    Param when(bool (*pred)(const T&)) const {
        Param p = *this;
        p.shown = pred;
        return p;
    }
};

// The tables. RenderSettings: the scene's "settings" object; Projection: a camera payload;
// Material: one entry of "materials"; Light: a light payload.
template <class T>
std::span<const Param<T>> params();
template <>
std::span<const Param<RenderSettings>> params<RenderSettings>();
template <>
std::span<const Param<Projection>> params<Projection>();
template <>
std::span<const Param<Material>> params<Material>();
template <>
std::span<const Param<Light>> params<Light>();

template <class T>
const Param<T>* findParam(std::string_view key) {
    for (const Param<T>& p : params<T>())
        if (p.key == key) return &p;
    return nullptr;
}
template <class T>
const Param<T>* findParamByFlag(std::string_view flag) {
    for (const Param<T>& p : params<T>())
        if (!p.flag.empty() && p.flag == flag) return &p;
    return nullptr;
}

// "" when `v` is of the parameter's kind and inside its range, else "KEY must be in [LO, HI]"
// (or the kind it expects).
std::string checkValue(std::string_view key, ParamKind kind, double min, double max, const ParamValue& v);
template <class T>
std::string checkValue(const Param<T>& p, const ParamValue& v) {
    return checkValue(p.key, p.kind, p.min, p.max, v);
}
// Every parameter of `object` in its range: "" or the first that is not.
template <class T>
std::string checkParams(const T& object) {
    for (const Param<T>& p : params<T>())
        if (std::string e = checkValue(p, p.get(object)); !e.empty()) return e;
    return {};
}

// A value typed by a person (command line, `set KEY VALUE`) for a parameter of `kind`:
// bool on/off/true/false/yes/no/1/0; numbers; a colour as "r,g,b" or "[r, g, b]" (linear);
// a choice by name (quotes allowed). nullopt and `error` set when it does not parse.
std::optional<ParamValue> parseParamText(ParamKind kind, std::string_view text, std::string& error);
// The value as a person types it (the inverse of parseParamText): "on", "4", "0.25", "0.1,0.2,0.3", "flat".
std::string formatParamValue(const ParamValue& v);

// Sets `key` of `object` from text, range-checked: "" or a one-line error naming the key.
template <class T>
std::string setParamFromText(T& object, const Param<T>& p, std::string_view text) {
    std::string err;
    std::optional<ParamValue> v = parseParamText(p.kind, text, err);
    if (!v) return std::string(p.key) + ": " + err;
    if (p.kind == ParamKind::Choice && !p.set(object, *v)) {
        std::string names;
        for (const ParamChoice& c : p.choices) names += (names.empty() ? "" : ", ") + std::string(c.name);
        return std::string(p.key) + ": '" + std::string(text) + "' is not one of " + names;
    }
    if (std::string e = checkValue(p, *v); !e.empty()) return e;
    if (!p.set(object, *v)) return std::string(p.key) + ": cannot take '" + std::string(text) + "'";
    return {};
}

// The keys of the parameters whose values differ between a and b, comma-separated, in table
// order ("fog.mode, fog.start"): the undo labels ("Change fog.mode").
template <class T>
std::string changedParams(const T& a, const T& b) {
    std::string names;
    for (const Param<T>& p : params<T>())
        if (p.get(a) != p.get(b)) names += (names.empty() ? "" : ", ") + std::string(p.key);
    return names;
}

// --- building rows (used by params.cpp; public so tests and new tables can use them) ------------

namespace param_detail {
template <class M>
struct MemberOf;
template <class T, class V>
struct MemberOf<V T::*> {
    using Owner = T;
    using Value = V;
};

template <auto P>
using Owner = typename MemberOf<decltype(P)>::Owner;
template <auto P>
using Value = typename MemberOf<decltype(P)>::Value;

template <class E>
std::vector<ParamChoice> choicesOf() {
    std::vector<ParamChoice> out;
    for (const auto& e : nameTable<E>().entries) out.push_back({e.name, e.label, e.help});
    return out;
}

template <auto P>
ParamValue get(const Owner<P>& t) {
    using V = Value<P>;
    if constexpr (std::is_enum_v<V>)
        return std::string(nameOf(t.*P));
    else
        return ParamValue(t.*P);
}
template <auto P>
bool set(Owner<P>& t, const ParamValue& v) {
    using V = Value<P>;
    if constexpr (std::is_enum_v<V>) {
        const std::string* s = std::get_if<std::string>(&v);
        return s && parseName(*s, t.*P);
    } else {
        const V* x = std::get_if<V>(&v);
        if (x) t.*P = *x;
        return x != nullptr;
    }
}
}   // namespace param_detail

// A row for member P (its kind from the member's type; a choice's names from its name table).
template <auto P>
Param<param_detail::Owner<P>> field(std::string_view key, std::string_view flag, std::string_view label, std::string_view help) {
    using V = param_detail::Value<P>;
    Param<param_detail::Owner<P>> p;
    p.key = key;
    p.flag = flag;
    p.label = label;
    p.help = help;
    p.get = &param_detail::get<P>;
    p.set = &param_detail::set<P>;
    if constexpr (std::is_same_v<V, bool>)
        p.kind = ParamKind::Bool;
    else if constexpr (std::is_same_v<V, int>)
        p.kind = ParamKind::Int;
    else if constexpr (std::is_same_v<V, float>)
        p.kind = ParamKind::Float;
    else if constexpr (std::is_same_v<V, vec3>)
        p.kind = ParamKind::Color;
    else if constexpr (std::is_same_v<V, std::string>)
        p.kind = ParamKind::Text;
    else {
        static_assert(std::is_enum_v<V>, "a parameter is bool, int, float, vec3, std::string or an enum with a name table");
        p.kind = ParamKind::Choice;
        p.choices = param_detail::choicesOf<V>();
    }
    return p;
}

}   // namespace sg
