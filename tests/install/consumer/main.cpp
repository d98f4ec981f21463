// A downstream program built against the installed Flexfit package.
#include <flexfit/flexfit.hpp>

#include <cstdio>

int main() {
    const auto model = flexfit::buildPartModel(flexfit::makeTorus1());
    flexfit::PartState state = flexfit::PartState::atRest(*model);
    flexfit::stepFullModel(*model, flexfit::SimulationSettings{}, {}, state);
    std::printf("consumer: %s %zu springs\n", model->name.c_str(), model->springCount());
    return model->springCount() == 1728 ? 0 : 1;
}
