# SPDX-License-Identifier: GPL-2.0-or-later
# Links every entry of the installed YADE's plugin folder FROM (its libraries and its py/ folder)
# into TO, the private prefix's (CMakeLists.txt).
file(GLOB entries RELATIVE ${FROM} ${FROM}/*)
foreach(e ${entries})
  file(CREATE_LINK ${FROM}/${e} ${TO}/${e} SYMBOLIC)
endforeach()
