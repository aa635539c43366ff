#pragma once
// The dashboard's one page (client/dashboard/web/dashboard.html, built into the program): the
// fleet view and the model view, drawn in the browser from /api JSON, updated by /events. It
// loads nothing else: no script, font or style from the internet.
#include <string>

namespace dynid::dashboard {

const std::string& page();

}  // namespace dynid::dashboard
