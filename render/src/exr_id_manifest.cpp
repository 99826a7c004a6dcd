#include "exr_id_manifest.h"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <initializer_list>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace csgrt::detail {

namespace {

/// Bytes laid out as OpenEXR's IDManifest serialisation writes them: Xdr integers (little
/// endian), and the variable-length integers of its tables (7 bits a byte, low bits first).
class ManifestBytes {
public:
    std::vector<char> bytes;

    void int32(std::uint32_t value) {
        for (int shift = 0; shift < 32; shift += 8) bytes.push_back(char((value >> shift) & 255));
    }
    void byte(unsigned value) { bytes.push_back(char(value & 255)); }
    void varint(std::uint64_t value) {
        do {
            const unsigned low = unsigned(value & 127);
            value >>= 7;
            byte(value > 0 ? low | 128 : low);
        } while (value > 0);
    }
    void text(std::string_view text) { bytes.insert(bytes.end(), text.begin(), text.end()); }
    /// A list of strings as the manifest's headers store them: count, lengths, then the bytes.
    void strings(std::initializer_list<std::string_view> list) {
        int32(std::uint32_t(list.size()));
        for (const std::string_view text : list) varint(text.size());
        for (const std::string_view text : list) this->text(text);
    }
    /// A string with its 32-bit length first.
    void pascal(std::string_view text) {
        int32(std::uint32_t(text.size()));
        this->text(text);
    }
};

}  // namespace

Imf::CompressedIDManifest id_manifest(const ExrMetadata& metadata, int zip_level) {
    const std::size_t objects = metadata.objects.size();
    // The strings in order of first use, with their counts; each entry's three strings.
    std::vector<std::string_view> strings;
    std::vector<std::uint64_t> uses;
    std::vector<std::uint32_t> entries;
    strings.reserve(objects + 16);
    uses.reserve(objects + 16);
    entries.reserve(3 * objects);
    std::unordered_map<std::string_view, std::uint32_t> repeated;
    const auto add = [&](std::string_view text, bool look_up) {
        if (look_up) {
            const auto [found, added] =
                repeated.try_emplace(text, static_cast<std::uint32_t>(strings.size()));
            if (!added) {
                ++uses[found->second];
                entries.push_back(found->second);
                return;
            }
        }
        entries.push_back(static_cast<std::uint32_t>(strings.size()));
        strings.push_back(text);
        uses.push_back(1);
    };
    for (const ExrObject& object : metadata.objects) {
        add(object.name, false);
        add(object.shape, true);
        add(object.material, true);
    }
    // Listed by count, the most used first; equal counts in order of first use.
    std::vector<std::uint32_t> order(strings.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return uses[a] > uses[b]; });
    std::vector<std::uint32_t> code(strings.size());
    for (std::uint32_t k = 0; k < order.size(); ++k) code[order[k]] = k;

    ManifestBytes out;
    out.int32(0);  // version
    // The string table: count, each stored string's length, then the stored strings, where a
    // string after the first starts with how many bytes it shares with the one before (two
    // bytes, high first, when that one is longer than 255; at most 65535 shared).
    ManifestBytes stored;
    out.int32(static_cast<std::uint32_t>(strings.size()));
    for (std::size_t k = 0; k < order.size(); ++k) {
        const std::string_view text = strings[order[k]];
        std::size_t shared = 0;
        const std::size_t start = stored.bytes.size();
        if (k > 0) {
            const std::string_view previous = strings[order[k - 1]];
            const std::size_t most = std::min({previous.size(), text.size(), std::size_t{65535}});
            while (shared < most && previous[shared] == text[shared]) ++shared;
            if (previous.size() > 255) stored.byte(unsigned(shared >> 8));
            stored.byte(unsigned(shared));
        }
        stored.text(text.substr(shared));
        out.varint(stored.bytes.size() - start);
    }
    out.bytes.insert(out.bytes.end(), stored.bytes.begin(), stored.bytes.end());
    // Codes to strings: the run 0 ... n - 1, so code k is string k.
    out.int32(strings.empty() ? 0 : 1);
    if (!strings.empty()) {
        out.int32(0);
        out.int32(static_cast<std::uint32_t>(strings.size() - 1));
    }
    // One channel group: "id", its components, lifetime, hash and encoding schemes, then the
    // table with ids stored as variable-length differences (scheme 2), each with its codes.
    out.int32(1);
    out.strings({"id"});
    out.strings({"name", "shape", "material"});
    // Ids are indices into the scene's objects: they change when the scene file does.
    out.byte(Imf::IDManifest::LIFETIME_SHOT);
    out.pascal(Imf::IDManifest::NOTHASHED);
    out.pascal(Imf::IDManifest::ID_SCHEME);
    out.byte(2);
    out.int32(static_cast<std::uint32_t>(objects));
    for (std::size_t id = 0; id < objects; ++id) {
        out.varint(id == 0 ? 0 : 1);
        for (int component = 0; component < 3; ++component) {
            out.varint(code[entries[3 * id + static_cast<std::size_t>(component)]]);
        }
    }
    if (out.bytes.size() > std::size_t{std::numeric_limits<int>::max()} / 2) {
        throw std::runtime_error("the id manifest of " + std::to_string(objects) +
                                 " objects takes more than 1 GiB");
    }
    // zlib's fastest level, as the pixels'.
    uLong compressed_size = ::compressBound(static_cast<uLong>(out.bytes.size()));
    auto* data = static_cast<unsigned char*>(std::malloc(compressed_size));
    if (data == nullptr) throw std::bad_alloc();
    if (::compress2(data, &compressed_size, reinterpret_cast<const Bytef*>(out.bytes.data()),
                    static_cast<uLong>(out.bytes.size()), zip_level) != Z_OK) {
        std::free(data);
        throw std::runtime_error("cannot compress the id manifest");
    }
    // CompressedIDManifest owns its data and frees it with free().
    Imf::CompressedIDManifest manifest;
    manifest._data = data;
    manifest._compressedDataSize = static_cast<int>(compressed_size);
    manifest._uncompressedDataSize = out.bytes.size();
    return manifest;
}


}  // namespace csgrt::detail
