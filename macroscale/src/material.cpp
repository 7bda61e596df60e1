// Material interface anchor: keeps the vtable of knit::macro::Material in one object file.
#include "knit/macro/material.hpp"
