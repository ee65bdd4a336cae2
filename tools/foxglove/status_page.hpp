// The status page `horus foxglove` serves at / : one self-contained HTML document (its style and script inline, nothing
// fetched from elsewhere) that reads /status.json every second and shows the fleet's hosts, the topics with rate and
// bandwidth, and the Foxglove clients.
#pragma once

#include <string_view>

namespace horus::tools::fox {

std::string_view status_page_html();

}  // namespace horus::tools::fox
