// Placeholder: tessellation lands with the tessellation work (marching cubes etc.).
#include "renderers/tessellate.h"

namespace rnd {

Tessellation tessellate(const sg::DrawAnalytic&, int) {
    Tessellation t;
    t.mesh = std::make_shared<sg::Mesh>();
    return t;
}

const Tessellation& TessellationCache::get(const sg::DrawAnalytic& a, int resolution) {
    std::lock_guard lock(m_mutex);
    uint64_t key = a.geometryKey * 1315423911u + uint64_t(resolution);
    auto& e = m_entries[key];
    if (!e.t.mesh) e.t = tessellate(a, resolution);
    e.lastUsed = m_frame;
    return e.t;
}

void TessellationCache::nextFrame(int maxAge) {
    std::lock_guard lock(m_mutex);
    ++m_frame;
    for (auto it = m_entries.begin(); it != m_entries.end();)
        it = m_frame - it->second.lastUsed > uint64_t(maxAge) ? m_entries.erase(it) : std::next(it);
}

size_t TessellationCache::size() const {
    std::lock_guard lock(m_mutex);
    return m_entries.size();
}

}  // namespace rnd
