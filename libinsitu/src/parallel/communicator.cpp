#include "insitu/parallel/communicator.hpp"

#include "insitu/error.hpp"

namespace insitu {

namespace {

class SingleProcessCommunicator final : public Communicator {
public:
    int rank() const override { return 0; }
    int size() const override { return 1; }
    void all_reduce(std::vector<double>&, Reduction) override {}
    std::vector<Bytes> all_gather(const Bytes& mine) override { return {mine}; }
    std::vector<Bytes> all_to_all(const std::vector<Bytes>& to_each) override {
        if (to_each.size() != 1) {
            fail<InvalidArgument>("all_to_all: ", to_each.size(), " messages for 1 rank");
        }
        return to_each;
    }
    std::vector<Bytes> gather(const Bytes& mine, int root) override {
        if (root != 0) fail<InvalidArgument>("gather: root ", root, " of 1 rank");
        return {mine};
    }
    void broadcast(Bytes&, int root) override {
        if (root != 0) fail<InvalidArgument>("broadcast: root ", root, " of 1 rank");
    }
    CommunicationCounters counters() const override { return {}; }
};

}  // namespace

std::shared_ptr<Communicator> single_process_communicator() {
    return std::make_shared<SingleProcessCommunicator>();
}

}  // namespace insitu
