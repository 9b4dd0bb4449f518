// A game's tool built against the installed package: one scenario of its own, then every detsim
// subcommand through detsim::cli::run_cli.
#include <detsim/cli.hpp>
#include <detsim/detsim.hpp>

int main(int argc, char** argv) {
  detsim::ScenarioDefinition game;
  game.name = "consumer_drop";
  game.summary = "a box dropped on a plane";
  game.default_frames = 120;
  game.build = [](detsim::World& world, const detsim::ScenarioParams&) {
    detsim::BodyDef ground;
    ground.type = detsim::BodyType::static_body;
    ground.shape = detsim::Shape::plane();
    (void)world.create_body(ground);
    detsim::BodyDef box;
    box.position = {detsim::Fixed::zero(), detsim::Fixed::from_int(3), detsim::Fixed::zero()};
    (void)world.create_body(box);
  };
  if (!detsim::register_scenario(game)) return 2;
  return detsim::cli::run_cli(argc, argv, "consumer-tool");
}
