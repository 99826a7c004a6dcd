#pragma once

// The EXR's idManifest, written by exr.cpp (render/src only).

#include <OpenEXR/ImfIDManifest.h>

#include "csgrt/render/exr.h"

namespace csgrt::detail {

/// The idManifest of the id part: one entry per scene object, id -> (name, shape, material),
/// serialised and compressed here in the layout of OpenEXR 3's IDManifest::serialize (version
/// 0), which readers decode with Imf::IDManifest. OpenEXR's own serialiser copies every entry
/// into a std::map and finds each of its strings in another std::map three times: it took
/// 4.9 s of a render of 10^6 objects named "object N". Here the shapes' kinds and the
/// materials, which repeat, are numbered once each through a hash map; names, nearly all
/// distinct, are not looked up at all: each is its own string of the table (a reader expands
/// every string the table lists, repeated or not). The table lists the strings by how often
/// they are used (the most common get one-byte codes, as OpenEXR's do), each after the first
/// starting with the length it shares with the one before it, and its code mapping is one run,
/// code k for string k.
/// `zip_level` is zlib's, as for the pixels.
Imf::CompressedIDManifest id_manifest(const ExrMetadata& metadata, int zip_level);

}  // namespace csgrt::detail
