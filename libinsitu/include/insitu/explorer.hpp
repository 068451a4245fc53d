#pragma once
// placeholder: the Explorer facade (written next)
